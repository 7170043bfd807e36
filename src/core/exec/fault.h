// A fault hook for tests: the n-th device launch from now (a kernel, a copy, a fill: the calls
// mem::count_launch counts, on either backend) throws wb::DeviceFault, as a kernel fault or a
// failed allocation would in the middle of a step. The studio's recovery from a fault mid-stroke
// is tested with it on the CPU backend (docs/RELIABILITY.md "Faults keep the painting").
#pragma once
#include <cstdint>

#include "core/exec/error.h"

namespace wb {

/// A failure of the device in the middle of work: a kernel fault, a failed launch or copy.
struct DeviceFault : Error {
  using Error::Error;
};

namespace mem {
/// Arms the hook: the `launches`-th launch from now, on any thread, throws DeviceFault; 0 disarms.
void inject_fault_after(int64_t launches);
}  // namespace mem

}  // namespace wb
