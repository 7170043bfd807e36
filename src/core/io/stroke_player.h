// Stroke input (Figure 4 step 1): replays a Stroke as simulation steps of the stroke's dt,
// each with the brush pose at its end, the number of sub-steps that keeps fast motion
// stable, the pen state and the paint events that fire in it. The one replay path used by
// the tests, `wetbrush replay`, `wetbrush bench` and the studio's recorded strokes.
#pragma once
#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "core/brush/brush_spec.h"
#include "core/io/pen_sample.h"
#include "core/io/stroke.h"

namespace wb {

/// One simulation step, covering (t_begin, t] on the stroke's clock.
struct PlayerStep {
  int64_t index = 0;        ///< 0 .. step_count() - 1
  double t_begin = 0.0;     ///< start of the step, seconds
  double t = 0.0;           ///< end of the step, seconds
  double dt = 0.0;          ///< t - t_begin (always the stroke's dt)
  int substeps = 1;         ///< n >= 1: simulate n sub-steps of dt / n
  float max_move = 0.f;     ///< largest displacement of a brush reference point in one sub-step, cells
  BrushPose pose;           ///< pose at t (sub-step k ends at pose_at(substep_time(step, k)))
  PenSample pen;            ///< interpolated pen at t (pressure = max(elevation, 0))
  float elevation = -1.f;   ///< interpolated elevation at t (see pen_elevation)
  bool pen_down = false;       ///< the brush is in contact (elevation >= 0) at some time in the step
  bool pen_down_edge = false;  ///< contact starts in this step: reload paint before simulating it
  bool pen_up_edge = false;    ///< contact ended: the previous step had contact, this one has none
  std::span<const StrokeEvent> events;  ///< events firing in this step, in time order
};

/// Seconds of hover between full lift and contact: a pen-up sample closer than this (in
/// time) to a pen-down sample is lifted only by that fraction of the full lift, and across a
/// longer gap the pen comes down (and goes up) in this time, fully lifted before (after).
inline constexpr double kLiftTime = 0.1;

/// Replays a stroke. Timeline: from t_begin() = first sample t - lead_in (the brush held
/// lifted above the first sample, descending to it) to t_end() = last sample t + lead_out
/// (rising above the last sample). Between keys x, y, elevation and tilt are linear and
/// twist follows the shortest angle; between pen-up samples the brush stays lifted (by less
/// within kLiftTime of a contact). Poses at pen-down sample times are the samples' poses.
class StrokePlayer {
 public:
  explicit StrokePlayer(Stroke stroke);

  const Stroke& stroke() const { return stroke_; }
  double t_begin() const { return keys_.front().t; }
  double t_end() const { return keys_.back().t; }
  /// t_end() - t_begin(), seconds.
  double duration() const { return t_end() - t_begin(); }
  /// ceil(duration / dt), at least 1; known before playing.
  int64_t step_count() const { return step_count_; }
  int64_t steps_done() const { return next_index_; }

  /// Fills `out` with the next step; false when all steps have been played.
  bool next(PlayerStep& out);
  /// Steps from the next one on in which the brush stays in the air (elevation below 0 from
  /// their start to their end) and no event fires, ending `margin` seconds before the pen starts
  /// down to its next contact; 0 after a step with contact.
  int64_t air_steps_ahead(double margin) const;
  /// Passes over the next n steps without playing them (a pause fast-forwarded).
  void skip(int64_t n);
  /// Back to the first step.
  void rewind();

  /// Interpolated pen at time t (clamped to [t_begin, t_end]); exact at sample times.
  PenSample pen_at(double t) const;
  float elevation_at(double t) const;
  /// Brush pose at time t: pose_from_pen(pen_at(t), elevation_at(t), brush).
  BrushPose pose_at(double t) const;
  /// End time of sub-step k (1..n) of a step.
  static double substep_time(const PlayerStep& step, int k) {
    return k >= step.substeps ? step.t : step.t_begin + step.dt * double(k) / double(step.substeps);
  }

 private:
  struct Key {
    double t;
    float x, y, e, tilt_x, tilt_y, twist;
    float twist_delta;  ///< shortest signed angle to the next key's twist, degrees
  };
  size_t segment(double t) const;
  Key interpolate(double t) const;
  /// Keys with ta < key.t < tb.
  std::pair<std::vector<Key>::const_iterator, std::vector<Key>::const_iterator> keys_inside(double ta, double tb) const;
  int substeps_for(double ta, double tb, float limit, float* max_move) const;
  /// Sub-step bound of a step with the pen up all through: a brush length, at least the stroke's.
  float lifted_move_limit() const { return std::max(stroke_.max_move_per_substep, stroke_.brush.length); }

  Stroke stroke_;
  std::vector<Key> keys_;
  int64_t step_count_ = 1;
  int64_t next_index_ = 0;
  size_t next_event_ = 0;
  bool prev_contact_ = false;
};

}  // namespace wb
