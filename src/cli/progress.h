// Progress of a long command on standard error. On a terminal one line is redrawn four times a
// second; into a file or a pipe (a log, CI) a whole line is written every 10 s, so that a log shows
// the run is alive and how far it has come. -q silences both.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

namespace wb::cli {

class Progress {
 public:
  /// enabled: false for -q. log_every_s: the interval of the lines written to a log.
  explicit Progress(bool enabled, double log_every_s = 10.0);
  /// Seconds since the progress began.
  double elapsed() const;
  /// Reports `done` of `total` steps, `what` before them (a name, or empty) and `detail` after
  /// (the simulated time); the step rate, the wall time and the time left are added. Written
  /// only when due; `last` always (the final count).
  void step(int64_t done, int64_t total, const std::string& what, const std::string& detail, bool last = false);
  /// Ends a terminal's redrawn line.
  void finish();

 private:
  bool enabled_, tty_;
  double every_, last_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace wb::cli
