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
#include "core/particles/adhesion_kernels.h"
#include "core/particles/flip_kernels.h"
#include "core/particles/mac_sample.h"
#include "core/particles/particle_fields.h"
#include "core/particles/particle_params.h"

namespace wb {

/// Two-step adhesion update of every particle (Eq. 8-10) over dt seconds. Needs the
/// particles' nearest / d_B from SampleGrid::query_nearest with a range >= prm.D1 on
/// the same samples. Positions and velocities are updated in place.
void particles_adhesion_step(const Device& d, const ParticleView& p, const SampleView& s, const SolidView& solid,
                             const ParticleParams& prm, float dt);
/// Adds the particles' mass (cell centres) and momentum and mass weight (MAC faces) into g,
/// trilinearly (flip_kernels.h); the mass only when the face fields are all null. Particles
/// outside the window are skipped.
void particles_rasterise(const Device& d, const ParticleView& p, const ParticleRasterView& g);
/// vel[c][f] = momentum / weight on faces with weight > 0, else `empty` (e.g. 0).
void particles_face_velocity(const Device& d, const ParticleRasterView& g, float* const vel[3], float empty);
/// Eq. 11 for every particle: before = joint field u before projection, after = u_bar.
void particles_flip_pic(const Device& d, const ParticleView& p, const MacView& before, const MacView& after,
                        float gamma);

/// Particles whose dead flag is clear; used by ParticleStore::compact.
void particles_keep_flags(const Device& d, const uint32_t* dead, uint32_t* keep, int64_t n);
/// to[pos[i]] = the state of particle i for every i < n with !dead[i]; pos is the exclusive scan
/// of the keep flags (ParticleStore::compact).
void particles_compact_state(const Device& d, const ParticleView& p, const ParticleStateView& to, const uint32_t* pos,
                             int64_t n);
/// Sort keys by half cell: keys[k] = the half cell (a window cell halved along each axis) of
/// particle k, numbered x fastest over the window of `dims` cells at canvas cell `origin` (the
/// half cells' count for a particle outside it or not finite), index[k] = k.
void particles_cell_keys(const Device& d, const ParticleView& p, Int3 origin, Int3 dims, uint32_t* keys,
                         uint32_t* index);
/// to[i] = the state of particle from[i] for i < n: the particles in a new order
/// (ParticleStore::sort_by_cell).
void particles_gather_state(const Device& d, const ParticleView& p, const ParticleStateView& to, const uint32_t* from,
                            int64_t n);
/// Height fields of what the particles rest on over the window's columns (SolidView), absolute
/// canvas z, nx * ny floats each: `height`, the top of the highest dried cell (dryness at or above
/// dry_threshold, the grid's solid test) as a whole cell (the grid holds one state a cell, so
/// wet paint over a partly filled dried cell starts at its top; column_solid_top gives the paint's
/// own top), or floor_z where none; `wet_top` (nullable), the top
/// of the highest liquid cell above it, or `height` where none. Liquid is the grid's joint test:
/// density plus `particle_density` (the particles' raster, nullable) at or above liquid_threshold;
/// where the layer near the bristles is mostly particles (§5.2), its grid density alone is air.
void particles_solid_height(const Device& d, const PaintWindowView& pw, const float* particle_density,
                            float dry_threshold, float liquid_threshold, float floor_z, float* height,
                            float* wet_top = nullptr);
/// The ground a particle in flight lands on, per window column (absolute canvas z): the solid's
/// top (as `height` above), raised through the liquid cells (joint test) stacked on it up to the
/// first that is not. Paint held up in the air above a gap is not ground.
void particles_ground_surface(const Device& d, const PaintWindowView& pw, const float* particle_density,
                              float dry_threshold, float liquid_threshold, float floor_z, float* surface);
/// Scratch of particles [first, first + n): nearest = -1, d_B = 0, dead = 0.
void particles_init_scratch(const Device& d, const ParticleView& p, int64_t first, int64_t n);

#define WB_PARTICLES_BACKEND_DECLS                                                                                 \
  void particles_adhesion_step(ParticleView p, SampleView s, SolidView solid, ParticleParams prm, float dt);      \
  void particles_rasterise(ParticleView p, ParticleRasterView g);                                                \
  void particles_face_velocity(ParticleRasterView g, float* u, float* v, float* w, float empty);                 \
  void particles_flip_pic(ParticleView p, MacView before, MacView after, float gamma);                           \
  void particles_keep_flags(const uint32_t* dead, uint32_t* keep, int64_t n);                                    \
  void particles_compact_state(ParticleView p, ParticleStateView to, const uint32_t* pos, int64_t n);               \
  void particles_init_scratch(ParticleView p, int64_t first, int64_t n);                                         \
  void particles_cell_keys(ParticleView p, Int3 origin, Int3 dims, uint32_t* keys, uint32_t* index);             \
  void particles_gather_state(ParticleView p, ParticleStateView to, const uint32_t* from, int64_t n);               \
  void particles_ground_surface(PaintWindowView pw, const float* particle_density, float dry_threshold,          \
                                float liquid_threshold, float floor_z, float* surface);                          \
  void particles_solid_height(PaintWindowView pw, const float* particle_density, float dry_threshold,            \
                              float liquid_threshold, float floor_z, float* height, float* wet_top);

namespace cpu {
WB_PARTICLES_BACKEND_DECLS
}  // namespace cpu
namespace cuda {
WB_PARTICLES_BACKEND_DECLS
}  // namespace cuda
#undef WB_PARTICLES_BACKEND_DECLS

}  // namespace wb
