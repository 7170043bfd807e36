// Allocation and copies on either backend. CPU memory is 64-byte aligned host memory.
#include "core/exec/memory.h"

#include <atomic>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <cstring>
#include <mutex>
#include <new>
#include <unordered_map>

#include <omp.h>

#include "core/exec/dispatch.h"
#include "core/exec/fault.h"
#include "core/exec/parallel_for.h"
#if defined(WB_WITH_CUDA)
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb::mem {
namespace {
// Allocation is never on the per-step path (buffers are sized once and grown geometrically),
// so a mutex-guarded map is cheap enough for the books.
struct Ledger {
  std::mutex m;
  std::unordered_map<const void*, size_t> size;
  Usage use[2];
  size_t budget[2] = {0, 0};
};
Ledger& ledger() {
  static Ledger l;
  return l;
}
/// fn(lo, hi) over [0, bytes) in one slice a thread where the range is large: one thread's memcpy
/// or memset reaches about half the memory's bandwidth here (a 14 MB copy, the window's three
/// velocities: 1.0-1.25 ms on one thread, 0.5-0.66 on two of the 2-core VM), and the others wait.
template <class F>
void in_slices(size_t bytes, F fn) {
  constexpr size_t kMinSlice = size_t(1) << 20;
  if (bytes < 2 * kMinSlice) {
    fn(size_t(0), bytes);
    return;
  }
  const int64_t lines = int64_t((bytes + 63) / 64);  // whole cache lines a thread
#pragma omp parallel
  {
    int64_t lo, hi;
    thread_slice(lines, omp_get_thread_num(), omp_get_num_threads(), lo, hi);
    const size_t a = size_t(lo) * 64, b = std::min(bytes, size_t(hi) * 64);
    if (b > a) fn(a, b);
  }
}
/// Refuses an allocation the budget has no room for, before the system is asked.
void check_budget(size_t bytes, bool cuda) {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  const size_t b = l.budget[cuda], held = l.use[cuda].in_use;
  if (b > 0 && held + bytes > b)
    WB_THROW("out of the memory budget: " + format_bytes(double(bytes)) + " more of " + (cuda ? "GPU" : "host") +
             " memory would hold " + format_bytes(double(held + bytes)) + ", over the budget of " +
             format_bytes(double(b)) + " (--memory-limit)");
}
void booked(const void* p, size_t bytes, bool cuda) {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  l.size[p] = bytes;
  Usage& u = l.use[cuda];
  u.in_use += bytes;
  if (u.in_use > u.peak) u.peak = u.in_use;
}
void unbooked(const void* p, bool cuda) noexcept {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  const auto it = l.size.find(p);
  if (it == l.size.end()) return;
  l.use[cuda].in_use -= it->second;
  l.size.erase(it);
}
}  // namespace

Usage usage(bool cuda) {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  return l.use[cuda];
}

void reset_peak() {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  for (Usage& u : l.use) u.peak = u.in_use;
}

void set_budget(bool cuda, size_t bytes) {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  l.budget[cuda] = bytes;
}

size_t budget(bool cuda) {
  Ledger& l = ledger();
  std::lock_guard<std::mutex> lock(l.m);
  return l.budget[cuda];
}

namespace {
/// The first number in a file (a cgroup's memory.max or memory.current); nothing for "max".
std::optional<uint64_t> number_in(const char* path) {
  std::ifstream in(path);
  uint64_t v = 0;
  if (in >> v) return v;
  return std::nullopt;
}
}  // namespace

size_t available(const Device& device) {
  if (device.is_cpu()) {
    uint64_t avail = 0;
    std::ifstream info("/proc/meminfo");
    std::string key;
    uint64_t kib = 0;
    std::string unit;
    while (info >> key >> kib >> unit)
      if (key == "MemAvailable:") {
        avail = kib * 1024;
        break;
      }
    // A container's own limit, where it is lower than the machine's (cgroup v2).
    const auto max = number_in("/sys/fs/cgroup/memory.max"), cur = number_in("/sys/fs/cgroup/memory.current");
    if (max && cur) avail = std::min<uint64_t>(avail ? avail : *max, *max > *cur ? *max - *cur : 0);
    return size_t(avail);
  }
#if defined(WB_WITH_CUDA)
  size_t free_bytes = 0, total = 0;
  device.activate();
  WB_CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total));
  return free_bytes;
#else
  detail::throw_no_cuda();
#endif
}

size_t room(const Device& device) {
  const bool cuda = !device.is_cpu();
  size_t r = available(device);
  const size_t b = budget(cuda), held = usage(cuda).in_use;
  if (b > 0) r = std::min(r, b > held ? b - held : size_t(0));
  return r;
}

std::string format_bytes(double bytes) {
  char buf[64];
  if (bytes >= double(1 << 30))
    std::snprintf(buf, sizeof buf, "%.2f GiB", bytes / double(1 << 30));
  else if (bytes >= double(1 << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", bytes / double(1 << 20));
  else
    std::snprintf(buf, sizeof buf, "%.0f bytes", bytes);
  return buf;
}

size_t parse_size(const std::string& text) {
  const auto bad = [&] {
    WB_THROW("memory size '" + text + "': expected a number of bytes, or one with K, M, G or T (e.g. 512M, 4G)");
  };
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    bad();
  }
  std::string unit = text.substr(used);
  for (char& ch : unit) ch = char(std::toupper(static_cast<unsigned char>(ch)));
  if (unit.size() > 1 && (unit.substr(1) == "B" || unit.substr(1) == "IB")) unit = unit.substr(0, 1);
  double scale = 1.0;
  if (unit.empty() || unit == "B") scale = 1.0;
  else if (unit == "K") scale = 1024.0;
  else if (unit == "M") scale = 1024.0 * 1024.0;
  else if (unit == "G") scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T") scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else bad();
  const double bytes = v * scale;
  if (!std::isfinite(bytes) || bytes < 1024.0 * 1024.0 || bytes > 1e18)
    WB_THROW("memory size '" + text + "': expected from 1M to 1000000T");
  return size_t(bytes);
}

void set_budget_from(const std::string& text) {
  if (text.empty()) return;
  const size_t b = parse_size(text);
  set_budget(false, b);
  set_budget(true, b);
}

namespace {
thread_local int64_t t_host_reads = 0;  // per thread: the studio's UI and simulation threads apart
thread_local int64_t t_launches = 0;
}  // namespace
int64_t host_reads() { return t_host_reads; }
void count_host_read() { ++t_host_reads; }
int64_t launches() { return t_launches; }

namespace {
// The fault hook (fault.h): launches left before the injected fault; 0 when disarmed.
std::atomic<int64_t> g_fault_in{0};
}  // namespace

void inject_fault_after(int64_t launches) { g_fault_in.store(launches > 0 ? launches : 0); }

void count_launch() {
  ++t_launches;
  if (g_fault_in.load(std::memory_order_relaxed) > 0 && g_fault_in.fetch_sub(1) == 1)
    throw DeviceFault("the device failed in the middle of a step (an injected fault)");
}

void* allocate(const Device& device, size_t bytes) {
  if (bytes == 0) bytes = 1;
  check_budget(bytes, !device.is_cpu());
  if (device.is_cpu()) {
    void* p = std::aligned_alloc(64, (bytes + 63) & ~size_t(63));
    if (!p) WB_THROW("out of host memory allocating " + std::to_string(bytes) + " bytes");
    booked(p, bytes, false);
    return p;
  }
#if defined(WB_WITH_CUDA)
  void* p = nullptr;
  device.activate();
  WB_CUDA_CHECK(cudaMalloc(&p, bytes));
  booked(p, bytes, true);
  return p;
#else
  detail::throw_no_cuda();
#endif
}

void release(const Device& device, void* ptr) noexcept {
  if (!ptr) return;
  unbooked(ptr, !device.is_cpu());
  if (device.is_cpu()) {
    std::free(ptr);
    return;
  }
#if defined(WB_WITH_CUDA)
  cudaFree(ptr);  // errors here would be sticky ones already reported by the failing call
#endif
}

void copy_to_host(const Device& device, void* host_dst, const void* dev_src, size_t bytes) {
  count_host_read();
  count_launch();
  if (device.is_cpu()) {
    std::memcpy(host_dst, dev_src, bytes);
    return;
  }
#if defined(WB_WITH_CUDA)
  WB_CUDA_CHECK(cudaMemcpyAsync(host_dst, dev_src, bytes, cudaMemcpyDeviceToHost, cuda_stream()));
  WB_CUDA_CHECK(cudaStreamSynchronize(cuda_stream()));
#else
  detail::throw_no_cuda();
#endif
}

void copy_from_host(const Device& device, void* dev_dst, const void* host_src, size_t bytes) {
  count_launch();
  if (device.is_cpu()) {
    std::memcpy(dev_dst, host_src, bytes);
    return;
  }
#if defined(WB_WITH_CUDA)
  // The host source may be a temporary: from pageable memory (all the host memory this program
  // copies from) the copy returns once the driver has staged the source, so the caller may
  // free it at once without a wait (CUDA's "API synchronization behavior").
  WB_CUDA_CHECK(cudaMemcpyAsync(dev_dst, host_src, bytes, cudaMemcpyHostToDevice, cuda_stream()));
#else
  detail::throw_no_cuda();
#endif
}

void copy_on_device(const Device& device, void* dst, const void* src, size_t bytes) {
  count_launch();
  if (device.is_cpu()) {
    // As cudaMemcpy's, the two ranges do not overlap.
    in_slices(bytes, [&](size_t lo, size_t hi) {
      std::memcpy(static_cast<char*>(dst) + lo, static_cast<const char*>(src) + lo, hi - lo);
    });
    return;
  }
#if defined(WB_WITH_CUDA)
  WB_CUDA_CHECK(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyDeviceToDevice, cuda_stream()));
#else
  detail::throw_no_cuda();
#endif
}

void fill_zero(const Device& device, void* ptr, size_t bytes) {
  count_launch();
  if (device.is_cpu()) {
    in_slices(bytes, [&](size_t lo, size_t hi) { std::memset(static_cast<char*>(ptr) + lo, 0, hi - lo); });
    return;
  }
#if defined(WB_WITH_CUDA)
  WB_CUDA_CHECK(cudaMemsetAsync(ptr, 0, bytes, cuda_stream()));
#else
  detail::throw_no_cuda();
#endif
}

}  // namespace wb::mem
