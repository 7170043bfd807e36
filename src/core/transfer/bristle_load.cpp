// The paint on the brush (paper §5.1): loading, dipping, wiping, cleaning and the UI sums.
#include "core/transfer/bristle_load.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/color/ryb.h"
#include "core/exec/algorithms.h"
#include "core/exec/error.h"
#include "core/transfer/transfer.h"

namespace wb {
namespace {

void validate(const PaintLoad& p, const char* what) {
  for (int c = 0; c < 3; ++c)
    WB_REQUIRE(std::isfinite(p.ryb[c]) && p.ryb[c] >= 0.f && p.ryb[c] <= 1.f,
               std::string(what) + ": pigment component " + std::to_string(c) + " must lie in [0, 1]");
  WB_REQUIRE(std::isfinite(p.oil) && p.oil >= 0.f && p.oil <= 1.f, std::string(what) + ": oil must lie in [0, 1]");
  WB_REQUIRE(std::isfinite(p.load) && p.load >= 0.f && p.load <= 1.f, std::string(what) + ": load must lie in [0, 1]");
}

}  // namespace

BristleLoad::BristleLoad(const Device& device, int64_t samples, const TransferParams& params)
    : device_(device), count_(samples) {
  WB_REQUIRE(samples >= 0, "BristleLoad: negative sample count");
  WB_REQUIRE(std::isfinite(params.M_max) && params.M_max > 0.f, "BristleLoad: M_max must be positive");
#define WB_X(name, doc)    \
  name.set_device(device); \
  name.resize(size_t(samples));
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
  scratch_.set_device(device);
  change_.set_device(device);
  change_.resize(1);
  change_.fill_zero();
  ws_ = Workspace(device);
  scratch_.resize(size_t(samples));
  BristleLoadHost h;
#define WB_X(name, doc) h.name.assign(size_t(samples), 0.f);
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
  const float cm = params.cell_mass();
  h.potential.assign(size_t(samples), params.M_max);
  h.capacity.assign(size_t(samples), params.M_max);
  h.radius.assign(size_t(samples), std::cbrt(3.f * params.M_max / (4.f * 3.14159265f * cm)));
  from_host(h);
}

BristleLoadView BristleLoad::view() {
  BristleLoadView v{};
#define WB_X(name, doc) v.name = name.data();
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
  v.count = count_;
  return v;
}

void BristleLoad::fill(const PaintLoad& paint) { load(paint, true, "BristleLoad::fill"); }

void BristleLoad::dip(const PaintLoad& paint) { load(paint, false, "BristleLoad::dip"); }

void BristleLoad::load(const PaintLoad& paint, bool replace, const char* what) {
  validate(paint, what);
  if (count_ == 0) return;
  transfer_load_dip(device_, view(), exchange_.empty() ? nullptr : exchange_.data(),
                    Vec3(paint.ryb[0], paint.ryb[1], paint.ryb[2]), paint.oil, paint.load, replace ? 1 : 0,
                    scratch_.data());
  reduce_sum_add_into(device_, scratch_.data(), count_, sink(), ws_);
}

void BristleLoad::set_dip_exchange(const std::vector<float>& x) {
  WB_REQUIRE(int64_t(x.size()) == count_, "BristleLoad::set_dip_exchange: one value a sample");
  for (float v : x) WB_REQUIRE(std::isfinite(v) && v >= 0.f && v <= 1.f, "BristleLoad::set_dip_exchange: values in [0, 1]");
  exchange_.set_device(device_);
  exchange_.resize(x.size());
  exchange_.copy_from_host(x.data(), x.size());
}

void BristleLoad::wipe(float fraction) {
  WB_REQUIRE(std::isfinite(fraction) && fraction >= 0.f && fraction <= 1.f,
             "BristleLoad::wipe: the fraction must lie in [0, 1], got " + std::to_string(fraction));
  if (count_ == 0) return;
  transfer_load_scale(device_, view(), 1.f - fraction, scratch_.data());
  reduce_sum_add_into(device_, scratch_.data(), count_, sink(), ws_);
}

void BristleLoad::clean() {
  if (count_ == 0) return;
  // A fill with nothing: no load, no pigment (white), no oil.
  transfer_load_dip(device_, view(), nullptr, Vec3(0.f, 0.f, 0.f), 0.f, 0.f, 1, scratch_.data());
  reduce_sum_add_into(device_, scratch_.data(), count_, sink(), ws_);
}

double BristleLoad::take_change() {
  double kg = 0.0;
  change_.copy_to_host(&kg, 1);
  change_.fill_zero();
  return kg;
}

double BristleLoad::total_mass(Workspace& ws) const { return reduce_sum(device_, m.data(), count_, ws); }

Vec3 BristleLoad::mean_color(Workspace& ws) { return mean_color(total_mass(ws), ws); }

float BristleLoad::mean_oil(Workspace& ws) { return mean_oil(total_mass(ws), ws); }

Vec3 BristleLoad::mean_color(double w, Workspace& ws) {
  if (!(w > 0.0)) return Vec3(0.f, 0.f, 0.f);
  double sums[4];
  const float* comp[3] = {pigment_r.data(), pigment_y.data(), pigment_b.data()};
  for (int c = 0; c < 3; ++c) {
    transfer_product(device_, m.data(), comp[c], scratch_.data(), count_);
    sums[c] = reduce_sum(device_, scratch_.data(), count_, ws);
  }
  transfer_load_brightness(device_, view(), scratch_.data());
  sums[3] = reduce_sum(device_, scratch_.data(), count_, ws);
  // Many-colour Algorithm 2: mass-weighted RYB mean, rescaled to the mass-weighted brightness.
  const Vec3 lin(float(sums[0] / w), float(sums[1] / w), float(sums[2] / w));
  return rescale_to_brightness(lin, float(sums[3] / w));
}

float BristleLoad::mean_oil(double w, Workspace& ws) {
  if (!(w > 0.0)) return 0.f;
  transfer_product(device_, m.data(), oil.data(), scratch_.data(), count_);
  return float(reduce_sum(device_, scratch_.data(), count_, ws) / w);
}

PaintLoad BristleLoad::mean_paint(Workspace& ws, const PaintLoad& clean) {
  PaintLoad out = clean;
  const double mass = total_mass(ws), capacity = reduce_sum(device_, potential.data(), count_, ws);
  out.load = capacity > 0.0 ? float(std::min(1.0, mass / capacity)) : 0.f;
  if (mass > 0.0) {
    const Vec3 c = mean_color(mass, ws);
    out.ryb[0] = c.x, out.ryb[1] = c.y, out.ryb[2] = c.z;
    out.oil = mean_oil(mass, ws);
  }
  return out;
}

BristleLoadHost BristleLoad::to_host() const {
  BristleLoadHost h;
#define WB_X(name, doc) h.name = name.to_host();
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
  return h;
}

void BristleLoad::from_host(const BristleLoadHost& h) {
#define WB_X(name, doc)                                                                                       \
  WB_REQUIRE(int64_t(h.name.size()) == count_, "BristleLoad::from_host: field '" #name "' has " +            \
                                                   std::to_string(h.name.size()) + " entries, the brush has " + \
                                                   std::to_string(count_) + " samples");
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
  for (size_t j = 0; j < h.m.size(); ++j)
    WB_REQUIRE(std::isfinite(h.m[j]) && h.m[j] >= 0.f,
               "BristleLoad::from_host: sample " + std::to_string(j) + " has a negative or non-finite load");
#define WB_X(name, doc) name.copy_from_host(h.name);
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
}

}  // namespace wb
