// Stroke replay at the simulation rate (Figure 4 step 1 input; DESIGN "Time": sub-steps
// when the brush moves more than a few cells in a step).
#include "core/io/stroke_player.h"

#include <algorithm>
#include <cmath>

#include "core/exec/error.h"
#include "core/io/pen_pose.h"

namespace wb {
namespace {

/// Shortest signed angle from a to b, degrees, in (-180, 180].
float shortest_angle(float a, float b) {
  float d = std::fmod(b - a, 360.f);
  if (d > 180.f) d -= 360.f;
  if (d <= -180.f) d += 360.f;
  return d;
}

/// Points whose motion bounds the bristles' motion: the ferrule centre, the ferrule's
/// four edge midpoints and the rest-shape tip.
constexpr int kRefPoints = 6;
void reference_points(const BrushPose& p, const BrushSpec& b, Vec3 out[kRefPoints]) {
  const Vec3 ex = p.rotation.col(0), ey = p.rotation.col(1), ez = p.rotation.col(2);
  out[0] = p.position;
  out[1] = p.position + ex * (0.5f * b.width);
  out[2] = p.position - ex * (0.5f * b.width);
  out[3] = p.position + ey * (0.5f * b.thickness);
  out[4] = p.position - ey * (0.5f * b.thickness);
  out[5] = p.position - ez * b.length;
}

float max_displacement(const Vec3 a[kRefPoints], const Vec3 b[kRefPoints]) {
  float m = 0.f;
  for (int i = 0; i < kRefPoints; ++i) m = std::max(m, length(b[i] - a[i]));
  return m;
}

}  // namespace

StrokePlayer::StrokePlayer(Stroke stroke) : stroke_(std::move(stroke)) {
  validate_stroke(stroke_);
  const auto& s = stroke_.samples;
  keys_.reserve(s.size() + 2);
  const auto key_of = [](const PenSample& p, double t, float e) {
    return Key{t, p.x, p.y, e, p.tilt_x, p.tilt_y, p.twist, 0.f};
  };
  if (stroke_.lead_in > 0) keys_.push_back(key_of(s.front(), s.front().t - stroke_.lead_in, -1.f));
  for (const PenSample& p : s) keys_.push_back(key_of(p, p.t, pen_elevation(p)));
  if (stroke_.lead_out > 0) keys_.push_back(key_of(s.back(), s.back().t + stroke_.lead_out, -1.f));
  // A pen-up sample near a contact is lifted in proportion to the time to that contact
  // (full lift kLiftTime away): a tablet goes from hover to touch within one 5 ms event,
  // and a brush dropped from full lift that fast would hit the canvas at ~10 m/s.
  {
    const size_t first = stroke_.lead_in > 0 ? 1 : 0;
    const size_t n = s.size();
    std::vector<double> prev_contact(n, -1e300), next_contact(n, 1e300);
    for (size_t i = 0; i < n; ++i) prev_contact[i] = s[i].down ? s[i].t : (i ? prev_contact[i - 1] : -1e300);
    for (size_t i = n; i-- > 0;) next_contact[i] = s[i].down ? s[i].t : (i + 1 < n ? next_contact[i + 1] : 1e300);
    for (size_t i = 0; i < n; ++i) {
      if (s[i].down) continue;
      const double gap = std::min(s[i].t - prev_contact[i], next_contact[i] - s[i].t);
      keys_[first + i].e = -float(std::min(1.0, gap / kLiftTime));
    }
  }
  // Across a gap longer than 2 kLiftTime in which the pen is not held down, the pen rises from
  // its last sample (or comes down to its next) in kLiftTime and is fully lifted for the rest:
  // a key at full lift kLiftTime from each end not already fully lifted, on the straight path
  // between the two samples. Without them the brush would sink towards the canvas for the whole
  // gap (an hour's pause: an hour's descent). The lead-in and lead-out keep their own descent
  // and rise.
  {
    const size_t first = stroke_.lead_in > 0 ? 1 : 0, end = first + s.size();
    std::vector<Key> keys;
    keys.reserve(keys_.size() + 2 * s.size());
    for (size_t i = 0; i < keys_.size(); ++i) {
      keys.push_back(keys_[i]);
      if (i < first || i + 1 >= end) continue;
      const Key &a = keys_[i], &b = keys_[i + 1];
      if (b.t - a.t <= 2.0 * kLiftTime || (a.e >= 0.f && b.e >= 0.f)) continue;
      const auto lifted_at = [&](double t) {
        const float f = float((t - a.t) / (b.t - a.t));
        return Key{t, a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), -1.f, a.tilt_x + f * (b.tilt_x - a.tilt_x),
                   a.tilt_y + f * (b.tilt_y - a.tilt_y), a.twist + f * shortest_angle(a.twist, b.twist), 0.f};
      };
      if (a.e > -1.f) keys.push_back(lifted_at(a.t + kLiftTime));
      if (b.e > -1.f) keys.push_back(lifted_at(b.t - kLiftTime));
    }
    keys_ = std::move(keys);
  }
  // Towards a contact the pen arrives, then comes down: from its last sample in the air it moves
  // at that height to above the contact in the first half of the time, and descends onto it in
  // the second (twice the rate of the lift in proportion above: a full lift in half kLiftTime).
  // Descending all the way along the straight path instead would lower the brush onto the canvas
  // before the contact and drag a trail to it from as far as the pen came (a landing 300 cells
  // away in 0.1 s). The lead-in keeps its own descent.
  {
    const size_t first = stroke_.lead_in > 0 ? 1 : 0, end = keys_.size() - (stroke_.lead_out > 0 ? 1 : 0);
    std::vector<Key> keys;
    keys.reserve(keys_.size() + s.size());
    for (size_t i = 0; i < keys_.size(); ++i) {
      keys.push_back(keys_[i]);
      if (i < first || i + 1 >= end) continue;
      const Key &a = keys_[i], &b = keys_[i + 1];
      if (!(a.e < 0.f && b.e >= 0.f)) continue;
      Key above = b;
      above.t = 0.5 * (a.t + b.t);
      above.e = a.e;
      keys.push_back(above);
    }
    keys_ = std::move(keys);
  }
  for (size_t i = 0; i + 1 < keys_.size(); ++i) keys_[i].twist_delta = shortest_angle(keys_[i].twist, keys_[i + 1].twist);
  // The tiny tolerance keeps an exact multiple of dt from gaining a step to rounding.
  step_count_ = std::max<int64_t>(1, int64_t(std::ceil(duration() / stroke_.dt - 1e-9)));
}

void StrokePlayer::rewind() {
  next_index_ = 0;
  next_event_ = 0;
  prev_contact_ = false;
}

size_t StrokePlayer::segment(double t) const {
  // Last key with key.t <= t, but never the last key (so that [i, i+1] is a segment).
  const auto it = std::upper_bound(keys_.begin(), keys_.end(), t, [](double v, const Key& k) { return v < k.t; });
  size_t i = it == keys_.begin() ? 0 : size_t(it - keys_.begin()) - 1;
  return keys_.size() < 2 ? 0 : std::min(i, keys_.size() - 2);
}

std::pair<std::vector<StrokePlayer::Key>::const_iterator, std::vector<StrokePlayer::Key>::const_iterator>
StrokePlayer::keys_inside(double ta, double tb) const {
  const auto by_t = [](const Key& k, double v) { return k.t < v; };
  const auto first = std::upper_bound(keys_.begin(), keys_.end(), ta, [](double v, const Key& k) { return v < k.t; });
  const auto last = std::lower_bound(first, keys_.end(), tb, by_t);
  return {first, last};
}

StrokePlayer::Key StrokePlayer::interpolate(double t) const {
  if (keys_.size() == 1 || t <= keys_.front().t) return keys_.front();
  if (t >= keys_.back().t) return keys_.back();
  const size_t i = segment(t);
  const Key& k0 = keys_[i];
  const Key& k1 = keys_[i + 1];
  // a = 0 reproduces k0 exactly, so poses at sample times are the samples' poses.
  const float a = float((t - k0.t) / (k1.t - k0.t));
  Key k = k0;
  k.t = t;
  k.x = k0.x + a * (k1.x - k0.x);
  k.y = k0.y + a * (k1.y - k0.y);
  k.e = k0.e + a * (k1.e - k0.e);
  k.tilt_x = k0.tilt_x + a * (k1.tilt_x - k0.tilt_x);
  k.tilt_y = k0.tilt_y + a * (k1.tilt_y - k0.tilt_y);
  k.twist = k0.twist + a * k0.twist_delta;
  return k;
}

PenSample StrokePlayer::pen_at(double t) const {
  const Key k = interpolate(t);
  PenSample p;
  p.t = t;
  p.x = k.x;
  p.y = k.y;
  p.pressure = std::max(k.e, 0.f);
  p.down = k.e >= 0.f;
  p.tilt_x = k.tilt_x;
  p.tilt_y = k.tilt_y;
  p.twist = k.twist;
  return p;
}

float StrokePlayer::elevation_at(double t) const { return interpolate(t).e; }

BrushPose StrokePlayer::pose_at(double t) const {
  const Key k = interpolate(t);
  PenSample p;
  p.x = k.x;
  p.y = k.y;
  p.tilt_x = k.tilt_x;
  p.tilt_y = k.tilt_y;
  p.twist = k.twist;
  return pose_from_pen(p, k.e, stroke_.brush);
}

int StrokePlayer::substeps_for(double ta, double tb, float limit, float* max_move) const {
  const int cap = stroke_.max_substeps;
  Vec3 a[kRefPoints], b[kRefPoints];
  // First guess: the longest reference-point path through this step, segment by segment
  // between the keys inside it (keys bend it).
  float path = 0.f;
  {
    constexpr int kChunks = 8;  // rotations make reference paths curved within a segment
    float per_point[kRefPoints] = {};
    reference_points(pose_at(ta), stroke_.brush, a);
    const auto segment = [&](double t0, double t1) {
      for (int c = 1; c <= kChunks; ++c) {
        reference_points(pose_at(t0 + (t1 - t0) * double(c) / kChunks), stroke_.brush, b);
        for (int i = 0; i < kRefPoints; ++i) per_point[i] += length(b[i] - a[i]);
        std::copy(b, b + kRefPoints, a);
      }
    };
    double t0 = ta;
    for (auto [it, end] = keys_inside(ta, tb); it != end; ++it) segment(t0, it->t), t0 = it->t;
    segment(t0, tb);
    for (float v : per_point) path = std::max(path, v);
  }
  int n = std::clamp(int(std::ceil(path / limit)), 1, cap);
  // Check the uniform sub-steps (speed varies within a step) and refine.
  for (;;) {
    float worst = 0.f;
    reference_points(pose_at(ta), stroke_.brush, a);
    for (int k = 1; k <= n; ++k) {
      const double t = k == n ? tb : ta + (tb - ta) * double(k) / double(n);
      reference_points(pose_at(t), stroke_.brush, b);
      worst = std::max(worst, max_displacement(a, b));
      std::copy(b, b + kRefPoints, a);
    }
    if (worst <= limit || n >= cap) {
      *max_move = worst;
      return n;
    }
    n = std::min(cap, std::max(n + 1, int(std::ceil(double(n) * worst / limit))));
  }
}

int64_t StrokePlayer::air_steps_ahead(double margin) const {
  if (prev_contact_ || next_index_ >= step_count_) return 0;
  const double dt = stroke_.dt, t0 = t_begin() + double(next_index_) * dt;
  if (!(elevation_at(t0) < 0.f)) return 0;
  // The elevation is linear between keys: the air lasts until the key before the first one at
  // or above the canvas, where the pen starts down.
  double until = t_end();
  const auto after = std::upper_bound(keys_.begin(), keys_.end(), t0, [](double t, const Key& k) { return t < k.t; });
  for (auto it = after; it != keys_.end(); ++it)
    if (it->e >= 0.f) {
      until = it == after ? t0 : std::prev(it)->t;
      break;
    }
  if (next_event_ < stroke_.events.size()) until = std::min(until, stroke_.events[next_event_].t - dt);
  const double span = until - margin - t0;
  if (!(span > 0.0)) return 0;
  return std::min<int64_t>(int64_t(std::floor(span / dt)), step_count_ - 1 - next_index_);
}

void StrokePlayer::skip(int64_t n) {
  WB_REQUIRE(n >= 0 && next_index_ + n < step_count_, "StrokePlayer::skip: the last step is always played");
  next_index_ += n;
}

bool StrokePlayer::next(PlayerStep& out) {
  if (next_index_ >= step_count_) return false;
  const double dt = stroke_.dt;
  const int64_t k = next_index_++;
  out.index = k;
  out.t_begin = t_begin() + double(k) * dt;
  out.t = t_begin() + double(k + 1) * dt;
  out.dt = dt;
  out.pen = pen_at(out.t);
  out.elevation = elevation_at(out.t);
  out.pose = pose_from_pen(out.pen, out.elevation, stroke_.brush);

  // Elevation is piecewise linear: its maximum over the step is at an end or a key.
  float e_max = std::max(elevation_at(out.t_begin), out.elevation);
  for (auto [it, end] = keys_inside(out.t_begin, out.t); it != end; ++it) e_max = std::max(e_max, it->e);
  out.pen_down = e_max >= 0.f;
  // The sub-step bound resolves contact. A pen up all the step holds the tips half a brush length
  // above the canvas (kPenUpLift): the bristles, simulated in the brush's frame (Eq. 2), only
  // swing with its acceleration, which a brush length a sub-step resolves (docs/FORMATS.md).
  const bool lifted = e_max <= -1.f;
  out.substeps = substeps_for(out.t_begin, out.t, lifted ? lifted_move_limit() : stroke_.max_move_per_substep,
                              &out.max_move);
  out.pen_down_edge = out.pen_down && !prev_contact_;
  out.pen_up_edge = !out.pen_down && prev_contact_;
  prev_contact_ = out.pen_down;

  // Each event fires once: in the first step ending at or after it (the last step takes the rest).
  const auto& ev = stroke_.events;
  const size_t first = next_event_;
  const bool last = next_index_ == step_count_;
  while (next_event_ < ev.size() && (last || ev[next_event_].t <= out.t)) ++next_event_;
  out.events = std::span<const StrokeEvent>(ev.data() + first, next_event_ - first);
  return true;
}

}  // namespace wb
