// Sample hash grid: validation and the one runtime dispatch.
#include "core/particles/hash_grid.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "core/exec/algorithms.h"
#include "core/exec/dispatch.h"

namespace wb {
namespace {
void keys(const Device& d, const Vec3* x, const Vec3* v, float rw, int64_t n, float inv_h, uint32_t mask, uint32_t* k,
          uint32_t* idx, int32_t* bounds, int32_t* coarse) {
  WB_DISPATCH(d, hash_grid_keys(x, v, rw, n, inv_h, mask, k, idx, bounds, coarse));
}
void ranges(const Device& d, const uint32_t* k, const uint32_t* idx, const Vec3* x, const Vec3* v, float rw, int64_t n,
            uint32_t* s, uint32_t* e, Vec3* sx) {
  WB_DISPATCH(d, hash_grid_ranges(k, idx, x, v, rw, n, s, e, sx));
}
void query(const Device& d, HashGridView g, ParticleView p, float r) { WB_DISPATCH(d, hash_grid_query(g, p, r)); }
}  // namespace

SampleHashGrid::SampleHashGrid(const Device& device) : device_(device) {
  keys_.set_device(device);
  index_.set_device(device);
  start_.set_device(device);
  end_.set_device(device);
  sorted_x_.set_device(device);
  bounds_.set_device(device);
  bounds_.resize(6);
  coarse_.set_device(device);
}

void SampleHashGrid::build(const SampleView& s, float cell_size, Workspace& ws, float rewind_dt) {
  WB_REQUIRE(std::isfinite(cell_size) && cell_size > 0.f,
             "SampleHashGrid::build: cell size must be positive, got " + std::to_string(cell_size));
  WB_REQUIRE(s.bristles >= 0 && s.per_bristle >= 0, "SampleHashGrid::build: negative sample counts");
  const int64_t n = s.count();
  WB_REQUIRE(n < (int64_t(1) << 31), "SampleHashGrid::build: too many samples (" + std::to_string(n) + ")");
  WB_REQUIRE(n == 0 || s.x != nullptr, "SampleHashGrid::build: sample positions are null");
  WB_REQUIRE(std::isfinite(rewind_dt) && rewind_dt >= 0.f, "SampleHashGrid::build: rewind time must be >= 0");
  WB_REQUIRE(rewind_dt == 0.f || n == 0 || s.v != nullptr, "SampleHashGrid::build: rewinding needs sample velocities");
  count_ = n;
  h_ = cell_size;
  // About two buckets per sample keeps collisions rare; at least 1024.
  int bits = 10;
  while ((int64_t(1) << bits) < 2 * n && bits < 30) ++bits;
  mask_ = (uint32_t(1) << bits) - 1u;
  const size_t buckets = size_t(mask_) + 1;
  if (start_.size() < buckets) {
    start_.grow_keep(buckets);
    end_.grow_keep(buckets);
    coarse_.grow_keep(buckets);
  }
  start_.fill_zero();
  end_.fill_zero();
  coarse_.fill_zero();
  if (keys_.size() < size_t(n)) {
    keys_.grow_keep(size_t(n));
    index_.grow_keep(size_t(n));
    sorted_x_.grow_keep(size_t(n));
  }
  keys(device_, s.x, s.v, rewind_dt, n, 1.f / h_, mask_, keys_.data(), index_.data(), bounds_.data(),
       coarse_.data());
  if (n == 0) return;
  sort_by_key(device_, keys_.data(), index_.data(), n, bits, ws);
  ranges(device_, keys_.data(), index_.data(), s.x, s.v, rewind_dt, n, start_.data(), end_.data(), sorted_x_.data());
}

HashGridView SampleHashGrid::view() const {
  return HashGridView{start_.data(), end_.data(), index_.data(), sorted_x_.data(), count_, h_, mask_, bounds_.data(),
                      coarse_.data()};
}

void SampleHashGrid::query_nearest(const ParticleView& p, float max_range) const {
  WB_REQUIRE(std::isfinite(max_range) && max_range > 0.f,
             "SampleHashGrid::query_nearest: range must be positive, got " + std::to_string(max_range));
  WB_REQUIRE(start_.size() > 0, "SampleHashGrid::query_nearest: build() was not called");
  WB_REQUIRE(p.count >= 0, "SampleHashGrid::query_nearest: negative particle count");
  query(device_, view(), p, max_range);
}

NearestSample nearest_sample_brute_force(const Vec3* samples, int64_t n, Vec3 p, float max_range) {
  float best_d2 = max_range * max_range;
  int32_t best = -1;
  for (int64_t i = 0; i < n; ++i) {
    const float d2 = length2(samples[i] - p);
    if (d2 < best_d2) {  // strict: the lowest index wins ties, as in the grid query
      best_d2 = d2;
      best = int32_t(i);
    }
  }
  return best >= 0 ? NearestSample{best, std::sqrt(best_d2)} : NearestSample{-1, max_range};
}

}  // namespace wb
