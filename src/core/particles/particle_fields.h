// Liquid particles near the brush (paper §4.3, §5): the per-particle state, listed
// once. The lists generate the owning buffers of ParticleStore, the POD view kernels
// take, host copies and compaction. Units: 1 cell = 0.2 mm, time in s, mass in kg.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

// X(type, name, description). State carried from step to step.
#define WB_PARTICLE_STATE_FIELDS(X)                                          \
  X(Vec3, x, "position, canvas cells")                                     \
  X(Vec3, v, "velocity, cells/s, canvas frame")                            \
  X(float, m, "mass, kg")                                                  \
  X(float, pigment_r, "RYB pigment, red component in [0, 1]")              \
  X(float, pigment_y, "RYB pigment, yellow component in [0, 1]")           \
  X(float, pigment_b, "RYB pigment, blue component in [0, 1]")             \
  X(float, oil, "oil density in [0, 1] (viscosity, transparency)")         \
  X(float, dryness, "dryness in [0, 1]; solid at the drying threshold")

// Per-step scratch, recomputed every step (never serialised).
#define WB_PARTICLE_SCRATCH_FIELDS(X)                                                        \
  X(int32_t, nearest, "index of the nearest bristle sample within the query range, -1: none") \
  X(float, d_B, "distance to the nearest bristle sample, cells, capped at the query range")   \
  X(uint32_t, dead, "1: remove at the next compaction (absorbed, moved to the grid)")

#define WB_PARTICLE_FIELDS(X) \
  WB_PARTICLE_STATE_FIELDS(X) \
  WB_PARTICLE_SCRATCH_FIELDS(X)

namespace wb {

/// A particle the compaction keeps: not dead and not left weightless (a window move's return to
/// the grid, transfer_to_grid_mark). A non-finite mass is kept, for the containment to count.
WB_HD WB_INLINE bool particle_kept(uint32_t dead, float m) { return !dead && !(m == 0.f); }

/// POD view of all particles: device pointers plus the live count. Passed by value.
struct ParticleView {
#define WB_X(type, name, doc) type* name;
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
  int64_t count;
};

/// The state fields alone (a second set of arrays, into which a sort or a compaction moves
/// every particle's state in one pass). Passed by value.
struct ParticleStateView {
#define WB_X(type, name, doc) type* name;
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
};

}  // namespace wb
