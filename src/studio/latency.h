// Pen-to-paint latency as the studio measures it: from a pen event (its time on the wall clock,
// as the canvas view received it) to the end of the first frame the view presents whose
// simulation consumed that event (docs/STUDIO.md "Pen-to-paint latency").
#pragma once
#include <cstddef>
#include <cstdint>
#include <deque>

namespace wb::studio {

/// When a pen event happened (wall_now) and the session time of the sample that carries it.
struct PenEventTime {
  double session_t = 0.0;
  double wall_t = 0.0;
};

/// A pen event on its way to the screen, wall_now times: when it happened, when the step that
/// reached its sample ended, and when the front image holding that step's paint was published.
struct InputTiming {
  double event = 0.0;
  double consumed = 0.0;
  double published = 0.0;
};

struct LatencySummary {
  int64_t count = 0;
  double median_ms = 0.0;
  double p95_ms = 0.0;  ///< nearest rank
};

/// The latencies one view measured, in the order they were presented.
class LatencyLog {
 public:
  /// A latency of `seconds`, presented at wall time `at`.
  void add(double seconds, double at);
  /// Latencies measured so far (an index for summary's `from`).
  int64_t count() const { return first_ + int64_t(entries_.size()); }
  /// Median and 95th percentile of the latencies from the `from`-th on (of those still kept).
  LatencySummary summary(int64_t from = 0) const;
  /// Median of the latencies presented in the second before `now`, ms; when none were, the last
  /// such median (-1 before any).
  double current_ms(double now);

 private:
  struct Entry {
    double at;
    float ms;
  };
  /// A long session keeps its last kKeep latencies.
  static constexpr size_t kKeep = size_t(1) << 20;
  std::deque<Entry> entries_;
  int64_t first_ = 0;  ///< index of entries_.front()
  double last_current_ = -1.0;
};

/// The latency's three parts, logged as each event is presented: to the step that consumed it
/// (the wait for the next sample and the simulation's lag), to the front image (the render's
/// turn), and to the screen (the view's frame).
struct LatencyParts {
  LatencyLog to_step, to_frame, to_screen;
  void add(const InputTiming& t, double presented) {
    to_step.add(t.consumed - t.event, presented);
    to_frame.add(t.published - t.consumed, presented);
    to_screen.add(presented - t.published, presented);
  }
};

}  // namespace wb::studio
