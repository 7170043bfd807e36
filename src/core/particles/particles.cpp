// Particle stage: the one runtime dispatch of its drivers (paper §4.3, particles_impl.h).
#include "core/particles/particles.h"

namespace wb {
WB_DEFINE_DISPATCHERS(WB_PARTICLES_KERNELS)
}  // namespace wb
