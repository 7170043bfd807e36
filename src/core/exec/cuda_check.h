// WB_CUDA_CHECK: every CUDA runtime call and every launch goes through it, so the
// first failure is reported with its file, line and CUDA's own message.
#pragma once
#include "core/exec/error.h"

#if defined(WB_WITH_CUDA) || defined(__CUDACC__)
#include <cuda_runtime.h>
#include <string>

namespace wb::detail {
inline void cuda_check(cudaError_t err, const char* expr, const char* file, int line) {
  if (err != cudaSuccess)
    ::wb::throw_error(file, line, std::string("CUDA error in ") + expr + ": " + cudaGetErrorName(err) + " (" +
                                      cudaGetErrorString(err) + ")");
}
}  // namespace wb::detail

#define WB_CUDA_CHECK(expr) ::wb::detail::cuda_check((expr), #expr, __FILE__, __LINE__)
#define WB_CUDA_CHECK_LAUNCH() ::wb::detail::cuda_check(cudaGetLastError(), "kernel launch", __FILE__, __LINE__)
#endif
