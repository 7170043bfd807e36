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

/// The span of an event's way to the screen a summary is of: the whole, or its part to the step
/// that consumed it (the wait for the next sample and the simulation's lag), to the front image
/// (the render's turn) or to the screen (the view's frame).
enum class LatencyPart { whole = 0, to_step, to_frame, to_screen };

/// The latencies one view measured, in the order they were presented, each with its parts.
class LatencyLog {
 public:
  /// The event `t`, presented at wall time `at`.
  void add(const InputTiming& t, double at);
  /// Latencies measured so far (an index for summary's `from`).
  int64_t count() const { return first_ + int64_t(entries_.size()); }
  /// Median and 95th percentile of `part` of the latencies from the `from`-th on (of those still
  /// kept).
  LatencySummary summary(int64_t from = 0, LatencyPart part = LatencyPart::whole) const;
  /// Median of the latencies presented in the second before `now`, ms; when none were, the last
  /// such median (-1 before any).
  double current_ms(double now);

 private:
  struct Entry {
    double at;
    float ms[4];  ///< by LatencyPart
  };
  /// A long session keeps its last kKeep latencies.
  static constexpr size_t kKeep = size_t(1) << 20;
  std::deque<Entry> entries_;
  int64_t first_ = 0;  ///< index of entries_.front()
  double last_current_ = -1.0;
};

}  // namespace wb::studio
