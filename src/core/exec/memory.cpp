// Allocation and copies on either backend. CPU memory is 64-byte aligned host memory.
#include "core/exec/memory.h"

#include <cstdlib>
#include <cstring>
#include <new>

#include "core/exec/dispatch.h"
#if defined(WB_WITH_CUDA)
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb::mem {

void* allocate(const Device& device, size_t bytes) {
  if (bytes == 0) bytes = 1;
  if (device.is_cpu()) {
    void* p = std::aligned_alloc(64, (bytes + 63) & ~size_t(63));
    if (!p) WB_THROW("out of host memory allocating " + std::to_string(bytes) + " bytes");
    return p;
  }
#if defined(WB_WITH_CUDA)
  void* p = nullptr;
  device.activate();
  WB_CUDA_CHECK(cudaMalloc(&p, bytes));
  return p;
#else
  detail::throw_no_cuda();
#endif
}

void release(const Device& device, void* ptr) noexcept {
  if (!ptr) return;
  if (device.is_cpu()) {
    std::free(ptr);
    return;
  }
#if defined(WB_WITH_CUDA)
  cudaFree(ptr);  // errors here would be sticky ones already reported by the failing call
#endif
}

void copy_to_host(const Device& device, void* host_dst, const void* dev_src, size_t bytes) {
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
  if (device.is_cpu()) {
    std::memcpy(dev_dst, host_src, bytes);
    return;
  }
#if defined(WB_WITH_CUDA)
  // Synchronous: the host source may be a temporary.
  WB_CUDA_CHECK(cudaMemcpyAsync(dev_dst, host_src, bytes, cudaMemcpyHostToDevice, cuda_stream()));
  WB_CUDA_CHECK(cudaStreamSynchronize(cuda_stream()));
#else
  detail::throw_no_cuda();
#endif
}

void copy_on_device(const Device& device, void* dst, const void* src, size_t bytes) {
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
