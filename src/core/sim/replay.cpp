#include "core/sim/replay.h"

#include <algorithm>
#include <cmath>

namespace wb {

CanvasRect stroke_region(const Stroke& stroke) {
  float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
  for (const PenSample& s : stroke.samples) {
    x0 = std::min(x0, s.x);
    y0 = std::min(y0, s.y);
    x1 = std::max(x1, s.x);
    y1 = std::max(y1, s.y);
  }
  if (stroke.samples.empty()) x0 = y0 = x1 = y1 = 0.f;
  const float reach = stroke.brush.length + std::max(stroke.brush.width, stroke.brush.thickness);
  CanvasRect r;
  r.x0 = std::max(0, int(std::floor(x0 - reach)));
  r.y0 = std::max(0, int(std::floor(y0 - reach)));
  const int xe = std::min(stroke.canvas.width, int(std::ceil(x1 + reach)) + 1);
  const int ye = std::min(stroke.canvas.height, int(std::ceil(y1 + reach)) + 1);
  r.width = std::max(1, xe - r.x0);
  r.height = std::max(1, ye - r.y0);
  return r;
}

Replay::Replay(Simulator& sim, StrokePlayer& player)
    : sim_(sim), player_(player), region_(stroke_region(player.stroke())), last_t_(player.t_begin()) {
  trace_.set_device(sim.device());
  trace_.resize(size_t(region_.width) * region_.height);
  trace_.fill_zero();
  const size_t steps = size_t(std::max<int64_t>(player_.step_count(), 1));
  contacts_.set_device(sim.device());
  contacts_.resize(steps);
  stretch_.set_device(sim.device());
  stretch_.resize(steps);
  poses_.reserve(size_t(std::max(1, player_.stroke().max_substeps)));
}

void drive_step(Simulator& sim, const StrokePlayer& player, const PlayerStep& step, std::span<const StrokeEvent> events,
                bool reload, std::vector<BrushPose>& poses) {
  for (const StrokeEvent& e : events) sim.apply(e);
  if (reload) sim.load_paint(player.stroke().paint);
  poses.clear();
  for (int k = 1; k <= step.substeps; ++k) poses.push_back(player.pose_at(StrokePlayer::substep_time(step, k)));
  sim.step(poses.data(), step.substeps, float(step.dt));
}

bool Replay::advance(const std::function<void(const BrushPose& end)>& before_step) {
  // A pause: the pen in the air for at least kMinRestSeconds more, no event, the paint at rest.
  // It is passed over in one call (Simulator::rest: the particles back into the grid, drying
  // for its length, the brush waiting where the pause ends), so that an hour's pause costs what
  // a step does. It ends kRestMargin before the pen starts down, which the brush then plays.
  // Shorter pauses are played: they save few steps, and passing over one settles the particles
  // left near the lifted brush into the grid, which playing it would not.
  constexpr double kMinRestSeconds = 2.0, kRestMargin = 0.25;
  const double dt = player_.stroke().dt;
  if (const int64_t n = player_.air_steps_ahead(kRestMargin); double(n) * dt >= kMinRestSeconds && sim_.paint_at_rest()) {
    const double t = player_.t_begin() + double(player_.steps_done() + n) * dt;
    sim_.rest(double(n) * dt, player_.pose_at(t));
    player_.skip(n);
    last_t_ = t;
  }
  PlayerStep step;
  if (!player_.next(step)) return false;
  if (before_step) before_step(player_.pose_at(step.t));
  drive_step(sim_, player_, step, step.events, step.pen_down_edge && player_.stroke().paint.reload_on_pen_down, poses_);
  // A bristle is in contact when a sample is within one cell of the canvas or dried paint.
  if (recorded_ == int64_t(contacts_.size())) {  // sized for the player's step count: not reached
    contacts_.grow_keep(size_t(recorded_) + 1);
    stretch_.grow_keep(size_t(recorded_) + 1);
  }
  sim_.mark_brush_contacts(trace_.data(), region_.width, region_.height, region_.x0, region_.y0,
                           contacts_.data() + recorded_, stretch_.data() + recorded_);
  ++recorded_;
  last_t_ = step.t;
  return true;
}

int64_t Replay::contact_cells_max() const {
  if (recorded_ == 0) return 0;
  std::vector<double> c(static_cast<size_t>(recorded_));
  contacts_.copy_to_host(c.data(), c.size());
  return int64_t(std::llround(*std::max_element(c.begin(), c.end())));
}

float Replay::max_stretch() const {
  if (recorded_ == 0) return 0.f;
  std::vector<float> s(static_cast<size_t>(recorded_));
  stretch_.copy_to_host(s.data(), s.size());
  return std::max(0.f, *std::max_element(s.begin(), s.end()));
}

std::vector<uint8_t> Replay::brush_image() const {
  const int w = region_.width, h = region_.height;
  std::vector<uint8_t> img(size_t(w) * h * 3);
  const std::vector<int32_t> trace = trace_.to_host();
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    const bool t = trace[i] != 0;
    img[3 * i + 0] = t ? 150 : 236;  // contact trace: a cool grey on primed-canvas white
    img[3 * i + 1] = t ? 160 : 232;
    img[3 * i + 2] = t ? 178 : 222;
  }
  // Bristles of the final pose, drawn from high to low so lower samples win, shaded by height.
  std::vector<Vec3> s = sim_.brush().samples_to_host();
  std::sort(s.begin(), s.end(), [](const Vec3& a, const Vec3& b) { return a.z > b.z; });
  const float top = std::max(1.f, sim_.brush().spec().length);
  for (const Vec3& p : s) {
    const int x = int(std::floor(p.x)) - region_.x0, y = int(std::floor(p.y)) - region_.y0;
    if (x < 0 || y < 0 || x >= w || y >= h || !std::isfinite(p.z)) continue;
    const float k = std::clamp(p.z / top, 0.f, 1.f);  // 0 on the canvas .. 1 a length above it
    const size_t i = (size_t(y) * w + x) * 3;
    img[i + 0] = uint8_t(90 + 110 * k);
    img[i + 1] = uint8_t(50 + 90 * k);
    img[i + 2] = uint8_t(20 + 60 * k);
  }
  return img;
}

}  // namespace wb
