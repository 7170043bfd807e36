// Joint fields (paper §4.3, DESIGN step 5): the particles' rasterised mass and momentum
// join the grid liquid before viscosity and projection; the grid velocity, kept between
// steps, is what drags the bristles (Eq. 2). Also the containment of non-finite state.
#pragma once
#include <cstdint>

#include "core/canvas/window.h"
#include "core/exec/device.h"
#include "core/grid/grid_fields.h"
#include "core/particles/flip_kernels.h"
#include "core/particles/particle_fields.h"

namespace wb {

/// out[i] = in[i] * scale (kg to cell-volume fractions and back).
void joint_scale(const Device& d, const float* in, float* out, int64_t n, float scale);
/// The particles' raster as densities: density[i] = cell[i].first * scale and, where oil is
/// not null, oil[i] = cell[i].second * scale (scale 1 / cell_mass: kg to cell-volume fractions).
void joint_raster_density(const Device& d, const FloatPair* cell, float* density, float* oil, int64_t n, float scale);
/// Blends the particles' face momentum into the grid's face velocity, per face:
/// u = (w_g u + P) / (w_g + W), w_g = cell_mass * mean density of the two cells (Eq. 11's u).
void joint_blend_velocity(const Device& d, GridView g, PaintWindowView paint, ParticleRasterView raster,
                          float cell_mass);
/// Replaces non-finite values by 0 in [n] floats; returns nothing (count them first).
void joint_zero_nonfinite(const Device& d, float* v, int64_t n);
/// Keeps particles inside the canvas box: its sides and floor are walls, so paint never leaves
/// the canvas (and is never deposited into off-canvas window cells, which are not stored).
void joint_clamp_to_canvas(const Device& d, ParticleView p, Vec3 lo, Vec3 hi);
/// Flags particles with any non-finite state as dead.
void joint_kill_nonfinite(const Device& d, ParticleView p);
/// Per sample below height z_top: x, -x, y and -y into out[0..n), [n..2n), [2n..3n), [3n..4n)
/// (-inf above z_top); their maxima are the horizontal box of the samples that reach the window.
void joint_sample_extent(const Device& d, const Vec3* x, int64_t n, float z_top, float* out);
/// Per window column: the dried paint's top (column_solid_top) where the column's centre lies
/// within r of (cx, cy) and the top is above floor_z, else 0 (their maximum is the ground under a
/// brush footprint). Only the columns under the footprint are scanned.
void joint_ground_under(const Device& d, PaintWindowView pw, float dry_threshold, float cx, float cy, float r,
                        float floor_z, float* out);

#define WB_JOINT_BACKEND_DECLS                                                                          \
  void joint_scale(const float* in, float* out, int64_t n, float scale);                               \
  void joint_raster_density(const FloatPair* cell, float* density, float* oil, int64_t n, float scale);   \
  void joint_blend_velocity(GridView g, PaintWindowView paint, ParticleRasterView raster, float cell_mass); \
  void joint_zero_nonfinite(float* v, int64_t n);                                                       \
  void joint_kill_nonfinite(ParticleView p);                                                            \
  void joint_clamp_to_canvas(ParticleView p, Vec3 lo, Vec3 hi);                                      \
  void joint_sample_extent(const Vec3* x, int64_t n, float z_top, float* out);                         \
  void joint_ground_under(PaintWindowView pw, float dry_threshold, float cx, float cy, float r, float floor_z, \
                          float* out);
namespace cpu {
WB_JOINT_BACKEND_DECLS
}
namespace cuda {
WB_JOINT_BACKEND_DECLS
}
#undef WB_JOINT_BACKEND_DECLS

}  // namespace wb
