// Per-stage timing. WB_PROFILE_SCOPE("grid.project") times the enclosing scope into
// the profiler installed on this thread (none: free), and counts the host reads made in it
// (mem::host_reads). On CUDA the scope synchronises at its ends so that the time is the
// stage's, not the launch's.
#pragma once
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "core/exec/device.h"
#include "core/exec/memory.h"

namespace wb {

class Profiler {
 public:
  explicit Profiler(Device device = {}) : device_(device) {}
  void add(const char* name, double ms, int64_t host_reads = 0) {
    samples_[name].push_back(ms);
    reads_[name].push_back(host_reads);
  }
  /// Median of the recorded samples of `name` in ms (0 when none).
  double median_ms(const std::string& name) const;
  double total_ms(const std::string& name) const;
  size_t count(const std::string& name) const;
  std::vector<std::string> names() const;
  /// Every recorded duration of `name`, in ms, in order.
  const std::vector<double>& samples(const std::string& name) const;
  /// Host reads (mem::host_reads) made in each recorded call of `name`, in order.
  const std::vector<int64_t>& host_reads(const std::string& name) const;
  void clear() {
    samples_.clear();
    reads_.clear();
  }
  const Device& device() const { return device_; }

  /// The profiler of the calling thread (may be null).
  static Profiler* current();
  static void set_current(Profiler* p);

 private:
  Device device_;
  std::map<std::string, std::vector<double>> samples_;
  std::map<std::string, std::vector<int64_t>> reads_;
};

class ProfileScope {
 public:
  explicit ProfileScope(const char* name) : name_(name), prof_(Profiler::current()) {
    if (prof_) {
      prof_->device().synchronize();
      reads_ = mem::host_reads();
      start_ = std::chrono::steady_clock::now();
    }
  }
  ~ProfileScope() {
    if (!prof_) return;
    prof_->device().synchronize();
    prof_->add(name_, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count(),
               mem::host_reads() - reads_);
  }
  ProfileScope(const ProfileScope&) = delete;
  ProfileScope& operator=(const ProfileScope&) = delete;

 private:
  const char* name_;
  Profiler* prof_;
  int64_t reads_ = 0;
  std::chrono::steady_clock::time_point start_{};
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
