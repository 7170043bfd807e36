#include "cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace wb::cli {

Progress::Progress(bool enabled, double log_every_s)
    : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0), every_(tty_ ? 0.25 : log_every_s),
      last_(tty_ ? -every_ : 0.0),  // a terminal's line at once, a log's first after the interval
      t0_(std::chrono::steady_clock::now()) {}

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

void Progress::step(int64_t done, int64_t total, const std::string& what, const std::string& detail, bool last) {
  if (!enabled_) return;
  const double now = elapsed();
  if (!last && now - last_ < every_) return;
  last_ = now;
  const double rate = double(done) / std::max(now, 1e-9);
  const double left = rate > 0.0 ? double(std::max<int64_t>(total - done, 0)) / rate : 0.0;
  char line[512];
  std::snprintf(line, sizeof line, "%s%sstep %lld/%lld  %s  %.2f steps/s  %.0f s elapsed, %.0f s left", what.c_str(),
                what.empty() ? "" : "  ", static_cast<long long>(done), static_cast<long long>(total), detail.c_str(),
                rate, now, left);
  if (tty_) {
    std::fprintf(stderr, "\r%s   ", line);
    drawn_ = true;
  } else {
    std::fprintf(stderr, "%s\n", line);
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (enabled_ && tty_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace wb::cli
