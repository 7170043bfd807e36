// WB_DISPATCH(device, call): the runtime switch of a stage dispatcher. It returns
// wb::cuda::call on a CUDA device, wb::cpu::call otherwise; a build without the
// CUDA backend answers "built without CUDA" instead of failing to link.
#pragma once
#include "core/exec/device.h"
#include "core/exec/error.h"

namespace wb::detail {
[[noreturn]] void throw_no_cuda();
}

#if defined(WB_WITH_CUDA)
#define WB_DISPATCH(device, call)                    \
  do {                                               \
    if ((device).is_cuda()) return ::wb::cuda::call; \
    return ::wb::cpu::call;                          \
  } while (0)
#else
#define WB_DISPATCH(device, call)                         \
  do {                                                    \
    if ((device).is_cuda()) ::wb::detail::throw_no_cuda(); \
    return ::wb::cpu::call;                               \
  } while (0)
#endif
