// The studio's session clock: turns pen input (press, move, hold, release) and palette actions
// into time-stamped PenSamples and StrokeEvents on one session time line that a StrokePlayer
// replays exactly. Times are multiples of 1/1024 s and every pause between strokes is the same
// fixed gap, so step boundaries (multiples of the 1/64 s step) are exact in floating point.
// See docs/STUDIO.md ("Time line and recording").
#pragma once
#include <optional>
#include <vector>

#include "core/io/stroke.h"
#include "studio/latency.h"

namespace wb::studio {

inline constexpr double kStepDt = 1.0 / 64.0;        ///< simulation step, seconds (exact in binary)
inline constexpr double kTimeQuantum = 1.0 / 1024.0; ///< sample time resolution, seconds
inline constexpr double kLiftGap = 0.125;             ///< hover before a press / lift after a release
inline constexpr double kStrokeGap = 0.25;            ///< session time between two strokes
/// Of the gap, what a press adds: the lifted brush's travel to the new spot (two steps) and its
/// descent (kLiftGap). The rest is added at the release, where the pen is known to stay, so that
/// it is simulated while the painter moves the pen, not after the press (docs/STUDIO.md).
inline constexpr double kTravel = 2.0 * kStepDt;
inline constexpr double kPressLead = kTravel + kLiftGap;
/// A recording's lead-in (the player's lead_in): two steps with the brush at its first sample,
/// above the canvas, before it moves.
inline constexpr double kLeadIn = 2.0 * kStepDt;
/// Silence of the pen after which it counts as held still and its last sample is repeated.
/// Longer than the gaps between the samples of a moving pen as the UI thread receives them (a
/// device's interval plus the UI's stalls): a repeat inside such a gap puts the pen's next move
/// a millisecond after it, and the brush must jump the sample's whole way in that millisecond.
inline constexpr double kHoldAfter = 0.1;

/// Pen values as the input device gives them (canvas cells, pressure after the curve).
struct PenInput {
  float x = 0.f, y = 0.f, pressure = 0.5f, tilt_x = 0.f, tilt_y = 0.f, twist = 0.f;
};

/// What one input produces: samples to append and events to append (both in time order).
struct ClockOutput {
  std::vector<PenSample> samples;
  std::vector<StrokeEvent> events;
  /// The pen event (press, move or release; not a held pen's repeat) whose sample this is, for
  /// the pen-to-paint latency: the simulation consumes it with the step that reaches its time.
  std::optional<PenEventTime> input;
};

class PenClock {
 public:
  PenClock(int canvas_width, int canvas_height) : w_(canvas_width), h_(canvas_height) {}

  /// `t` is when the input happened and `arrival` when it came, in seconds on the same
  /// monotonic clock (wall_now): samples are timed by the first, a held pen by the second.
  ClockOutput press(const PenInput& p, double t, double arrival);
  ClockOutput move(const PenInput& p, double t, double arrival);
  /// Repeats the last sample, a step apart, once the pen has been still for kHoldAfter (call
  /// from a timer).
  ClockOutput hold(double now);
  ClockOutput release(const PenInput& p, double t);
  /// While the pen is away and the paint still runs (an easel's drips): the lifted brush held where
  /// it is for the steps of session time the wall clock has run since the last sample, at most 4
  /// (call from a timer while the simulation has caught up).
  ClockOutput air(double now);
  /// The hold timer's tick: hold() while the pen is down, else air() where `paint_runs_on` (the
  /// simulation has caught up and its paint still runs: SimThread::paint_runs_on).
  ClockOutput tick(double now, bool paint_runs_on) {
    if (down_) return hold(now);
    return paint_runs_on ? air(now) : ClockOutput{};
  }
  /// A palette event (dip, wipe, clean, dry) while the pen is up: fires in the next step.
  ClockOutput event(StrokeEvent e);

  bool down() const { return down_; }
  /// Session time of the last sample (0 before any).
  double last_t() const { return last_t_; }
  /// Starts a new session time line (a new recording).
  void restart() { *this = PenClock(w_, h_); }

 private:
  PenSample sample(const PenInput& p, double t, bool down) const;
  double stamp(double t);
  void push(ClockOutput& out, const PenSample& s);

  int w_, h_;
  bool down_ = false;
  bool any_ = false;
  double last_t_ = 0.0;
  double press_session_t_ = 0.0, press_t_ = 0.0;
  double last_event_t_ = 0.0;  ///< when the last sample's input happened (a repeat: as held)
  double last_arrival_ = 0.0;  ///< arrival of the last sample, input or repeat
  double last_input_ = 0.0;    ///< arrival of the last input
  PenSample last_{};
};

/// Seconds on the steady clock: the arrival time of pen input and the studio's timings.
double wall_now();

/// Rounds t up to the next multiple of q (t itself when it is one).
double ceil_to(double t, double q);

}  // namespace wb::studio
