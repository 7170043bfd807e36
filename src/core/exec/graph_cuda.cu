// LaunchLoop's device side: the kernel that ends each pass of a recorded loop by setting its
// conditional node from the flag the body wrote.
#include <cstdint>

#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"

namespace wb::detail {
namespace {
__global__ void loop_condition_kernel(cudaGraphConditionalHandle handle, const uint32_t* go) {
  cudaGraphSetConditional(handle, *go != 0u ? 1u : 0u);
}
}  // namespace

void launch_loop_condition(unsigned long long handle, const uint32_t* go) {
  loop_condition_kernel<<<1, 1, 0, ::wb::cuda_stream()>>>(cudaGraphConditionalHandle(handle), go);
  WB_CUDA_CHECK_LAUNCH();
}
}  // namespace wb::detail
