// Allocation and copies on either backend. CPU memory is 64-byte aligned host memory.
#include "core/exec/memory.h"

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <unordered_map>

#include "core/exec/dispatch.h"
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
};
Ledger& ledger() {
  static Ledger l;
  return l;
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

namespace {
thread_local int64_t t_host_reads = 0;  // per thread: the studio's UI and simulation threads apart
thread_local int64_t t_launches = 0;
}  // namespace
int64_t host_reads() { return t_host_reads; }
void count_host_read() { ++t_host_reads; }
int64_t launches() { return t_launches; }
void count_launch() { ++t_launches; }

void* allocate(const Device& device, size_t bytes) {
  if (bytes == 0) bytes = 1;
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
    std::memmove(dst, src, bytes);
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
    std::memset(ptr, 0, bytes);
    return;
  }
#if defined(WB_WITH_CUDA)
  WB_CUDA_CHECK(cudaMemsetAsync(ptr, 0, bytes, cuda_stream()));
#else
  detail::throw_no_cuda();
#endif
}

}  // namespace wb::mem
