// Particle stage (paper §4.3, Eq. 8-11; DESIGN steps 4, 5 and 7): the per-step drivers a
// simulator step calls, in order:
//   SampleGrid::build -> query_nearest -> particles_adhesion_step -> particles_rasterise
//   -> (grid projection) -> particles_flip_pic.
// Each validates its input and dispatches to wb::cpu or wb::cuda (particles_impl.h).
#pragma once
#include <cstdint>

#include "core/brush/bristle_fields.h"
#include "core/canvas/window.h"
#include "core/exec/device.h"
#include "core/exec/dispatch.h"
#include "core/particles/adhesion_kernels.h"
#include "core/particles/flip_kernels.h"
#include "core/particles/mac_sample.h"
#include "core/particles/particle_fields.h"
#include "core/particles/particle_params.h"

namespace wb {

// The particle stage's backend drivers (particles_impl.h, where each is described), one list
// (core/exec/dispatch.h).
#define WB_PARTICLES_KERNELS(X)                                                                                        \
  X(void, particles_adhesion_step,                                                                                    \
    (ParticleView p, SampleView s, SolidView solid, ParticleParams prm, float dt, SampleMotion* motion),               \
    (p, s, solid, prm, dt, motion))                                                                                    \
  X(void, particles_rasterise, (ParticleView p, ParticleRasterView g), (p, g))                                         \
  X(void, particles_face_velocity, (ParticleRasterView g, float* u, float* v, float* w, float empty),                  \
    (g, u, v, w, empty))                                                                                               \
  X(void, particles_flip_pic, (ParticleView p, MacView before, MacView after, float gamma), (p, before, after, gamma)) \
  X(void, particles_keep_flags, (const uint32_t* dead, const float* m, uint32_t* keep, int64_t n), (dead, m, keep, n)) \
  X(void, particles_compact_state, (ParticleView p, ParticleStateView to, const uint32_t* pos, int64_t n),             \
    (p, to, pos, n))                                                                                                   \
  X(void, particles_init_scratch, (ParticleView p, int64_t first, int64_t n), (p, first, n))                           \
  X(void, particles_cell_keys, (ParticleView p, Int3 origin, Int3 dims, uint32_t * keys, uint32_t * index),            \
    (p, origin, dims, keys, index))                                                                                    \
  X(void, particles_gather_state, (ParticleView p, ParticleStateView to, const uint32_t* from, int64_t n),             \
    (p, to, from, n))                                                                                                  \
  X(void, particles_ground_surface,                                                                                    \
    (PaintWindowView pw, const float* particle_density, float dry_threshold, float liquid_threshold, float floor_z,    \
     float* surface),                                                                                                  \
    (pw, particle_density, dry_threshold, liquid_threshold, floor_z, surface))                                         \
  X(void, particles_solid_height,                                                                                      \
    (PaintWindowView pw, const float* particle_density, float dry_threshold, float liquid_threshold, float floor_z,    \
     float* height, float* wet_top),                                                                                   \
    (pw, particle_density, dry_threshold, liquid_threshold, floor_z, height, wet_top))
WB_DECLARE_KERNELS(WB_PARTICLES_KERNELS)

}  // namespace wb
