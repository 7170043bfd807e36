// Joint fields (paper §4.3, DESIGN step 5): the particles' rasterised mass and momentum
// join the grid liquid before viscosity and projection; the grid velocity, kept between
// steps, is what drags the bristles (Eq. 2). Also the containment of non-finite state.
#pragma once
#include <cstdint>

#include "core/canvas/window.h"
#include "core/exec/device.h"
#include "core/exec/dispatch.h"
#include "core/grid/grid_fields.h"
#include "core/particles/flip_kernels.h"
#include "core/particles/particle_fields.h"

namespace wb {

// The joint fields' backend drivers (joint_fields_impl.h, where each is described), one list
// (core/exec/dispatch.h).
#define WB_JOINT_KERNELS(X)                                                                                         \
  X(void, joint_scale, (const float* in, float* out, int64_t n, float scale), (in, out, n, scale))                  \
  X(void, joint_raster_density, (const FloatPair* cell, float* density, float* oil, TouchList list, int64_t n,      \
      float scale), (cell, density, oil, list, n, scale))                                                           \
  X(void, joint_clear_raster, (TouchList list, int64_t n, FloatPair* pairs, float* density, float* oil),            \
      (list, n, pairs, density, oil))                                                                               \
  X(void, joint_blend_velocity, (GridView g, PaintWindowView paint, ParticleRasterView raster, float cell_mass),    \
      (g, paint, raster, cell_mass))                                                                                \
  X(void, joint_zero_nonfinite, (float* v, int64_t n), (v, n))                                                      \
  X(void, joint_kill_nonfinite, (ParticleView p), (p))                                                              \
  X(void, joint_clamp_to_canvas, (ParticleView p, Vec3 lo, Vec3 hi), (p, lo, hi))                                   \
  X(void, joint_sample_extent, (const Vec3* x, int64_t n, float z_top, float* out), (x, n, z_top, out))             \
  X(void, joint_ground_under, (PaintWindowView pw, float dry_threshold, float cx, float cy, float r, float floor_z, \
      float* out), (pw, dry_threshold, cx, cy, r, floor_z, out))
WB_DECLARE_KERNELS(WB_JOINT_KERNELS)

}  // namespace wb
