// parallel_for(n, fn): the one loop construct of every stage driver. Under nvcc it is a
// grid-stride kernel on the simulator's stream (checked after launch); under g++ an
// OpenMP loop (guided chunks), serial below a size where threading costs more than it saves.
// The other loops here are built on it or mirror it: over a count the device wrote, with a sum,
// and over runs of consecutive elements.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/exec/memory.h"

#if defined(__CUDACC__)
#include <cub/block/block_reduce.cuh>

#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb {

/// Below this many elements the CPU backend runs serially (cheap per-element work).
inline constexpr int64_t kMinParallelSize = 2048;
/// For loops whose elements are heavy (a whole bristle per element): thread from a few on.
inline constexpr int64_t kMinParallelHeavy = 4;
/// parallel_sum_count: the CPU sums serially up to this many elements (as reduce_sum does).
inline constexpr int64_t kMinParallelSum = 65536;

/// Thread t's part of [0, n) of nt threads: contiguous, in thread order (the CPU's loops that
/// split their work by hand: the sort's and the scan's passes, large copies and fills).
inline void thread_slice(int64_t n, int t, int nt, int64_t& lo, int64_t& hi) {
  lo = n * t / nt;
  hi = n * (t + 1) / nt;
}

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
template <typename F>
__global__ void __launch_bounds__(256) parallel_sum_count_kernel(const int64_t* count, int64_t capacity, F fn,
                                                                 double* out, SumScratch s) {
  using Reduce = cub::BlockReduce<double, 256>;
  __shared__ typename Reduce::TempStorage tmp;
  __shared__ bool last;
  const int64_t n = *count < capacity ? *count : capacity;
  const int64_t stride = int64_t(blockDim.x) * gridDim.x;
  double v = 0.0;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) v += fn(i);
  const double block = Reduce(tmp).Sum(v);
  if (threadIdx.x == 0) {
    s.partial[blockIdx.x] = block;
    __threadfence();  // the partial is seen by whichever block finishes last
    last = atomicInc(s.ticket, gridDim.x - 1) == gridDim.x - 1;  // wraps the ticket to zero
  }
  __syncthreads();
  if (!last) return;
  // The last block sums the partials in block order: the same sum whatever order blocks ran in.
  __threadfence();
  double t = 0.0;
  for (unsigned b = threadIdx.x; b < gridDim.x; b += blockDim.x) t += static_cast<volatile double*>(s.partial)[b];
  __syncthreads();
  t = Reduce(tmp).Sum(t);
  if (threadIdx.x == 0) *out = t;
}
/// Blocks of kBlock threads for n elements, at most 2^20 (the kernels stride over the rest).
constexpr int kBlock = 256;
static_assert(kBlock == 256, "parallel_sum_count_kernel's block reduction is of 256 threads");
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
/// kernel wrote: the host never waits for it. CUDA launches at most kSumBlocks blocks (a full
/// GPU's resident threads) that stride to *count, so a large capacity (the viscous solve's: every
/// face of the window) costs no launch of blocks that only return; the CPU backend, whose device
/// memory is the host's, loops to *count.
template <typename F>
void parallel_for_count(const int64_t* count, int64_t capacity, F fn, int64_t serial_below = kMinParallelSize) {
  if (capacity <= 0) return;
#if defined(__CUDACC__)
  mem::count_launch();
  static_assert(__nv_is_extended_host_device_lambda_closure_type(F) || !__nv_is_extended_device_lambda_closure_type(F),
                "parallel_for_count takes __host__ __device__ (WB_HD) lambdas or functors");
  const unsigned blocks = detail::blocks_for(capacity) < unsigned(kSumBlocks) ? detail::blocks_for(capacity)
                                                                               : unsigned(kSumBlocks);
  detail::parallel_for_count_kernel<<<blocks, detail::kBlock, 0, ::wb::cuda_stream()>>>(count, capacity, fn);
  WB_CUDA_CHECK_LAUNCH();
#else
  parallel_for(*count < capacity ? *count : capacity, fn, serial_below);
#endif
}

/// *out = the sum of fn(i) over the first *count of `capacity` elements, fn returning a double
/// (and free to write its element's results): a pass and its dot product in one launch, left on
/// the device. The order of the sum is fixed for a given capacity (CUDA: kSumBlocks partials
/// summed in block order; CPU: OpenMP's static reduction, as reduce_sum), so a run repeats.
template <typename F>
void parallel_sum_count(const int64_t* count, int64_t capacity, F fn, double* out, SumScratch scratch) {
  mem::count_launch();
#if defined(__CUDACC__)
  if (capacity <= 0) {
    WB_CUDA_CHECK(cudaMemsetAsync(out, 0, sizeof(double), ::wb::cuda_stream()));
    return;
  }
  static_assert(__nv_is_extended_host_device_lambda_closure_type(F) || !__nv_is_extended_device_lambda_closure_type(F),
                "parallel_sum_count takes __host__ __device__ (WB_HD) lambdas or functors");
  const unsigned blocks = detail::blocks_for(capacity) < unsigned(kSumBlocks) ? detail::blocks_for(capacity)
                                                                               : unsigned(kSumBlocks);
  detail::parallel_sum_count_kernel<<<blocks, detail::kBlock, 0, ::wb::cuda_stream()>>>(count, capacity, fn, out,
                                                                                         scratch);
  WB_CUDA_CHECK_LAUNCH();
#else
  (void)scratch;
  const int64_t n = capacity <= 0 ? 0 : (*count < capacity ? *count : capacity);
  double s = 0.0;
#pragma omp parallel for reduction(+ : s) schedule(static) if (n > kMinParallelSum)
  for (int64_t i = 0; i < n; ++i) s += fn(i);
  *out = s;
#endif
}

/// Columns a column scan (a pass down every column of the window) takes together: on the CPU 16,
/// a cache line of floats a layer, scanned layer by layer without a branch a cell so that the
/// lanes vectorise (a column at a time, stopping at what it looked for, was four times slower:
/// docs/PERFORMANCE.md "Column scans"); on CUDA 1, a warp's threads being the lanes.
#if defined(__CUDACC__)
inline constexpr int kColumnLanes = 1;
#else
inline constexpr int kColumnLanes = 16;
#endif

/// fn(i0, lanes) for each run of Lanes consecutive elements (the last may be shorter) of n: the
/// run's lanes are elements i0 .. i0 + lanes - 1. Column scans take kColumnLanes columns a run.
template <int Lanes, typename F>
void parallel_for_runs(int64_t n, F fn) {
  const int64_t runs = (n + Lanes - 1) / Lanes;
  parallel_for(
      runs,
      [=] WB_HD(int64_t r) {
        const int64_t i0 = r * Lanes, left = n - i0;
        fn(i0, int(left < Lanes ? left : Lanes));
      },
      kMinParallelSize / Lanes);  // serial below as many elements as a loop over them
}

}  // namespace WB_BACKEND_NS
}  // namespace wb
