// Execution vocabulary shared by every kernel source: the only place that knows
// whether a function is compiled for the host, the device, or both.
#pragma once

#if defined(__CUDACC__)
#define WB_HD __host__ __device__
#define WB_DEVICE_FN __device__
#define WB_INLINE __forceinline__
#else
#define WB_HD
#define WB_DEVICE_FN
#define WB_INLINE inline
#endif

// Kernel assertions: checked on CPU debug builds, free on the device and in release.
#if defined(__CUDA_ARCH__) || defined(NDEBUG)
#define WB_KERNEL_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define WB_KERNEL_ASSERT(cond) assert(cond)
#endif

// The namespace a stage driver compiles into: wb::cpu under g++, wb::cuda under nvcc.
#if defined(__CUDACC__)
#define WB_BACKEND_NS cuda
#else
#define WB_BACKEND_NS cpu
#endif

namespace wb {
/// Blocks of a parallel_sum_count launch on CUDA, and its scratch: a partial sum a block, and a
/// ticket that is zero between launches (the last block to finish takes it back to zero).
inline constexpr int kSumBlocks = 1024;
struct SumScratch {
  double* partial = nullptr;       ///< kSumBlocks
  unsigned int* ticket = nullptr;  ///< zero before the first launch
};
}  // namespace wb
