// The single CUDA stream all simulator work is ordered on.
#pragma once
#if defined(WB_WITH_CUDA) || defined(__CUDACC__)
#include <cuda_runtime.h>
namespace wb {
/// The stream every kernel, copy and CUB call is queued on (per host thread).
inline cudaStream_t cuda_stream() { return cudaStreamPerThread; }
}  // namespace wb
#endif
