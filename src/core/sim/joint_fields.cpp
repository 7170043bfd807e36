// Joint fields: the one runtime dispatch of their drivers (joint_fields_impl.h).
#include "core/sim/joint_fields.h"

namespace wb {
WB_DEFINE_DISPATCHERS(WB_JOINT_KERNELS)
}  // namespace wb
