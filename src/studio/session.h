// The session time line and its recording: the studio's pen samples and palette events in
// session time (pen_clock.h), replayed step by step through the same StrokePlayer that
// `wetbrush replay` uses, so that a saved recording replays to the same canvas. The player is
// rebuilt in chunks from knots (samples on step boundaries whose keys agree in the chunk and in
// the whole recording), so new samples cost at most about half a second of steps to take in.
// Used by the simulation thread only, except recording() and from_blank().
#pragma once
#include <atomic>
#include <memory>
#include <mutex>
#include <span>

#include "core/io/stroke_player.h"
#include "studio/pen_clock.h"

namespace wb::studio {

/// What the step driver needs of the time line for one step.
struct SessionStep {
  PlayerStep step;
  std::span<const StrokeEvent> events;  ///< the events due in this step
  bool pen_down_edge = false;           ///< the session's own edge (a chunk may start pen-down)
  bool first = false;                   ///< the first step of this recording
  PenSample from;                       ///< the pen at the step's start
};

class SessionTimeline {
 public:
  /// Appends clock output (samples and events in time order).
  void append(const ClockOutput& out);
  /// Starts a new recording: `header` gives its canvas, brush, paint and simulation settings.
  void restart(Stroke header, bool from_blank);
  /// The recording so far (a copy; any thread).
  Stroke recording() const;
  /// True while the recording reproduces the canvas from a blank one (any thread).
  bool from_blank() const { return from_blank_.load(); }
  /// The samples so far allow another step. Inserts a knot during a long press.
  bool has_step();
  /// The next step the samples so far allow (false: none yet).
  bool next_step(SessionStep& out);
  /// The step ran: the time line has advanced to its end.
  void step_done(const SessionStep& s);
  /// The player of the current chunk (valid after next_step returned true).
  const StrokePlayer& player() const { return *player_; }
  const PaintLoad& paint() const { return rec_.paint; }
  /// The pen is down as of the last step.
  bool pen_down() const { return prev_contact_; }
  /// The pen is down as of the last sample appended (the painter's pen now).
  bool pen_down_now() const {
    std::lock_guard lk(mu_);
    return !rec_.samples.empty() && rec_.samples.back().down;
  }
  /// Any pen-down sample in this recording (something may have been painted).
  bool painted() const;
  /// Session time recorded but not simulated yet, s.
  double lag() const;

 private:
  void rebuild_player();

  mutable std::mutex mu_;       ///< guards rec_ against recording()
  Stroke rec_;
  size_t chunk_start_ = 0;      ///< sample index where the current player's stroke starts
  std::unique_ptr<StrokePlayer> player_;
  size_t player_samples_ = 0;   ///< samples the player was built with
  double t_done_ = 0.0;         ///< session time simulated so far (a step boundary)
  bool started_ = false;        ///< the first step of this recording has run
  size_t next_event_ = 0;
  bool prev_contact_ = false;
  std::atomic<bool> from_blank_{true};
};

}  // namespace wb::studio
