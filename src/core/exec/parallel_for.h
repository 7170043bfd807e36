// parallel_for(n, fn): the one loop construct of every stage driver. Under nvcc it is a
// grid-stride kernel on the simulator's stream (checked after launch); under g++ an
// OpenMP loop (guided chunks), serial below a size where threading costs more than it saves.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/exec/memory.h"

#if defined(__CUDACC__)
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb {

/// Below this many elements the CPU backend runs serially (cheap per-element work).
inline constexpr int64_t kMinParallelSize = 2048;
/// For loops whose elements are heavy (a whole bristle per element): thread from a few on.
inline constexpr int64_t kMinParallelHeavy = 4;

#if defined(__CUDACC__)
namespace detail {
template <typename F>
__global__ void parallel_for_kernel(int64_t n, F fn) {
  const int64_t stride = int64_t(blockDim.x) * gridDim.x;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) fn(i);
}
template <typename F>
__global__ void parallel_for_count_kernel(const int64_t* count, int64_t capacity, F fn) {
  const int64_t n = *count < capacity ? *count : capacity;
  const int64_t stride = int64_t(blockDim.x) * gridDim.x;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) fn(i);
}
/// Blocks of kBlock threads for n elements, at most 2^20 (the kernels stride over the rest).
constexpr int kBlock = 256;
inline unsigned blocks_for(int64_t n) {
  const int64_t blocks = (n + kBlock - 1) / kBlock;
  return unsigned(blocks > (int64_t(1) << 20) ? (int64_t(1) << 20) : blocks);
}
}  // namespace detail
#endif

namespace WB_BACKEND_NS {

template <typename F>
void parallel_for(int64_t n, F fn, int64_t serial_below = kMinParallelSize) {
  if (n <= 0) return;
  mem::count_launch();
#if defined(__CUDACC__)
  static_assert(__nv_is_extended_host_device_lambda_closure_type(F) || !__nv_is_extended_device_lambda_closure_type(F),
                "parallel_for takes __host__ __device__ (WB_HD) lambdas or functors");
  detail::parallel_for_kernel<<<detail::blocks_for(n), detail::kBlock, 0, ::wb::cuda_stream()>>>(n, fn);
  WB_CUDA_CHECK_LAUNCH();
#else
  if (n < serial_below) {
    for (int64_t i = 0; i < n; ++i) fn(i);
    return;
  }
  // Guided: chunks shrink as the loop drains, so a thread that was slowed (the other job on a
  // two-core machine, a vCPU's steal time, a run of costlier elements) does not hold the other
  // at the loop's end: a step 7 to 23 % faster than with static chunks here (docs/PERFORMANCE.md).
#pragma omp parallel for schedule(guided)
  for (int64_t i = 0; i < n; ++i) fn(i);
#endif
}

/// parallel_for over the first *count of `capacity` elements, where *count is device memory a
/// kernel wrote: the host never waits for it. CUDA launches over the capacity and the threads
/// past *count return; the CPU backend, whose device memory is the host's, loops to *count.
template <typename F>
void parallel_for_count(const int64_t* count, int64_t capacity, F fn, int64_t serial_below = kMinParallelSize) {
  if (capacity <= 0) return;
#if defined(__CUDACC__)
  mem::count_launch();
  static_assert(__nv_is_extended_host_device_lambda_closure_type(F) || !__nv_is_extended_device_lambda_closure_type(F),
                "parallel_for_count takes __host__ __device__ (WB_HD) lambdas or functors");
  detail::parallel_for_count_kernel<<<detail::blocks_for(capacity), detail::kBlock, 0, ::wb::cuda_stream()>>>(
      count, capacity, fn);
  WB_CUDA_CHECK_LAUNCH();
#else
  parallel_for(*count < capacity ? *count : capacity, fn, serial_below);
#endif
}

}  // namespace WB_BACKEND_NS
}  // namespace wb
