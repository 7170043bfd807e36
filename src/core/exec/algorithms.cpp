// The runtime dispatchers of the primitives: check the workspace, count, pick the backend.
#include "core/exec/algorithms.h"

#include <string>
#include <type_traits>

#include "core/exec/error.h"
#include "core/exec/memory.h"

namespace wb {
namespace {
void check_ws(const Device& d, const Workspace& ws) {
  WB_REQUIRE(ws.device() == d, "algorithm workspace lives on " + ws.device().to_string() + ", not " + d.to_string());
}
}  // namespace

void FloatArrays::add(const float* p, int64_t size) {
  WB_REQUIRE(count < kMax, "FloatArrays: more than " + std::to_string(kMax) + " arrays");
  WB_REQUIRE(size >= 0 && (size == 0 || p), "FloatArrays: a null array or a negative length");
  ptr[count] = p;
  n[count] = size;
  ++count;
}

// Every primitive checks its workspace and counts its launch, and the host read of one that
// returns a value (the step's counts of launches and waits, memory.h).
#define WB_ALGORITHMS_DISPATCHER(ret, name, params, args)       \
  ret name(const Device& device, WB_UNPAREN params) {           \
    check_ws(device, ws);                                       \
    mem::count_launch();                                        \
    if constexpr (!std::is_void_v<ret>) mem::count_host_read(); \
    WB_DISPATCH(device, name args);                             \
  }
WB_ALGORITHMS_KERNELS(WB_ALGORITHMS_DISPATCHER)
#undef WB_ALGORITHMS_DISPATCHER

}  // namespace wb
