// Per-stage timing. WB_PROFILE_SCOPE("grid.project") times the enclosing scope into
// the profiler installed on this thread (none: free), and counts the host reads and the
// launches made in it (mem::host_reads, mem::launches). On CUDA the scope synchronises at its
// ends so that the time is the stage's, not the launch's; those waits lengthen the step they
// break up, so a profiler set to `outermost` times only the outermost scope, as NAME:whole.
#pragma once
#include <chrono>
#include <string>
#include <vector>

#include "core/exec/device.h"
#include "core/exec/memory.h"

namespace wb {

class Profiler {
 public:
  explicit Profiler(Device device = {}) : device_(device) {}
  /// Records one call of the scope `name` (NAME:whole when `whole`). A scope's series is found
  /// by the address of its name (the literal of WB_PROFILE_SCOPE) before its text, so a step
  /// allocates nothing once each of its scopes has been seen, and clear() keeps the series.
  void add(const char* name, bool whole, double ms, int64_t host_reads = 0, int64_t launches = 0);
  /// Median of the recorded samples of `name` in ms (0 when none).
  double median_ms(const std::string& name) const;
  double total_ms(const std::string& name) const;
  size_t count(const std::string& name) const;
  /// The scopes with samples, in the order of their names.
  std::vector<std::string> names() const;
  /// Every recorded duration of `name`, in ms, in order.
  const std::vector<double>& samples(const std::string& name) const;
  /// Host reads (mem::host_reads) made in each recorded call of `name`, in order.
  const std::vector<int64_t>& host_reads(const std::string& name) const;
  /// Launches (mem::launches) made in each recorded call of `name`, in order.
  const std::vector<int64_t>& launches(const std::string& name) const;
  /// Forgets the samples; the series keep their storage (a long session clears it often).
  void clear();
  /// Time only the outermost scope (no synchronisation inside it), recorded as NAME:whole.
  void set_outermost(bool on) { outermost_ = on; }
  bool outermost() const { return outermost_; }
  const Device& device() const { return device_; }

  /// The profiler of the calling thread (may be null).
  static Profiler* current();
  static void set_current(Profiler* p);

 private:
  struct Series {
    std::string name;  ///< the scope's name, with ":whole" for an outermost-only record
    std::vector<double> ms;
    std::vector<int64_t> reads, launches;
  };
  struct Key {
    const char* literal;  ///< the address of a WB_PROFILE_SCOPE name
    bool whole;
    size_t series;
  };
  const Series* find(const std::string& name) const;

  Device device_;
  std::vector<Series> series_;
  std::vector<Key> keys_;
  bool outermost_ = false;
};

class ProfileScope {
 public:
  explicit ProfileScope(const char* name) : name_(name), prof_(Profiler::current()) {
    if (prof_ && prof_->outermost()) {
      open_ = &depth();
      if ((*open_)++ > 0) prof_ = nullptr;
    }
    if (prof_) {
      prof_->device().synchronize();
      reads_ = mem::host_reads();
      launches_ = mem::launches();
      start_ = std::chrono::steady_clock::now();
    }
  }
  ~ProfileScope() {
    if (open_) --*open_;
    if (!prof_) return;
    prof_->device().synchronize();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    prof_->add(name_, open_ != nullptr, ms, mem::host_reads() - reads_, mem::launches() - launches_);
  }
  ProfileScope(const ProfileScope&) = delete;
  ProfileScope& operator=(const ProfileScope&) = delete;

 private:
  const char* name_;
  Profiler* prof_;
  int64_t reads_ = 0, launches_ = 0;
  std::chrono::steady_clock::time_point start_{};
  int* open_ = nullptr;  // the open scopes of an outermost-only profiler on this thread
  static int& depth();
};

/// Installs a profiler on this thread for the lifetime of the guard.
class ProfilerGuard {
 public:
  explicit ProfilerGuard(Profiler* p) : prev_(Profiler::current()) { Profiler::set_current(p); }
  ~ProfilerGuard() { Profiler::set_current(prev_); }

 private:
  Profiler* prev_;
};

}  // namespace wb

#define WB_PROFILE_CAT2(a, b) a##b
#define WB_PROFILE_CAT(a, b) WB_PROFILE_CAT2(a, b)
#define WB_PROFILE_SCOPE(name) ::wb::ProfileScope WB_PROFILE_CAT(wb_profile_scope_, __LINE__)(name)
