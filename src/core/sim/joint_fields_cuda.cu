// CUDA backend of the joint-field kernels.
#include "core/sim/joint_fields_impl.h"
