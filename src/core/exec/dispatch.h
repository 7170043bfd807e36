// The one naming scheme of the backends. Each stage lists its backend drivers once, as
//   #define WB_GRID_KERNELS(X) X(void, grid_dry, (PaintWindowView pw, float amount), (pw, amount)) ...
// (return type, name, parameters, arguments). From that list WB_DECLARE_KERNELS declares
// wb::cpu::name and wb::cuda::name (defined once in the stage's *_impl.h, compiled by g++ and by
// nvcc) and the dispatcher wb::name(const Device&, parameters); WB_DEFINE_DISPATCHERS defines the
// dispatchers in the stage's .cpp. A grep for a driver's name finds its list entry, its one
// definition and every call. Drivers validate their own arguments (host code, both backends).
//
// WB_DISPATCH(device, call): the runtime switch of a dispatcher. It returns
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

#define WB_UNPAREN(...) __VA_ARGS__
#define WB_BACKEND_DECL(ret, name, params, args) ret name params;
#define WB_DISPATCHER_DECL(ret, name, params, args) ret name(const Device& device, WB_UNPAREN params);
#define WB_DISPATCHER_DEF(ret, name, params, args) \
  ret name(const Device& device, WB_UNPAREN params) { WB_DISPATCH(device, name args); }
/// Declares a stage's drivers on both backends and their dispatchers (inside namespace wb).
#define WB_DECLARE_KERNELS(LIST) \
  namespace cpu {                \
  LIST(WB_BACKEND_DECL)          \
  }                              \
  namespace cuda {               \
  LIST(WB_BACKEND_DECL)          \
  }                              \
  LIST(WB_DISPATCHER_DECL)
/// Defines a stage's dispatchers (inside namespace wb, in the stage's .cpp).
#define WB_DEFINE_DISPATCHERS(LIST) LIST(WB_DISPATCHER_DEF)
