// Brush stage drivers (paper §4.1), declared for both backends with their dispatchers. Defined
// once in brush_impl.h and compiled twice (brush_cpu.cpp, brush_cuda.cu); brush.cpp defines the
// dispatchers. Every function is one or a few parallel_for launches over device pointers.
#pragma once
#include <cstdint>

#include "core/brush/bristle_fields.h"
#include "core/brush/brush_views.h"
#include "core/canvas/window.h"
#include "core/exec/dispatch.h"
#include "core/exec/touch_list.h"

namespace wb {

/// Sorted hash grid over the vertices for the minimum-density constraint.
struct MinDensityGrid {
  const uint32_t* ids;         ///< vertex ids sorted by cell hash
  const uint32_t* cell_start;  ///< per hash bucket: first sorted index (start == end: empty)
  const uint32_t* cell_end;    ///< per hash bucket: one past the last sorted index
  uint32_t mask;               ///< table size - 1 (power of two)
  float h;                     ///< kernel radius = grid cell size, cells
  float rho0;                  ///< the density bound, W(s_min)
  float eps;                   ///< relaxation of the constraint's denominator
};

/// The previous step's sample values (for velocities and their rates).
struct SamplePrev {
  Vec3* x;
  Vec3* t;
  Vec3* n;
  Vec3* v;
  Vec3* omega;
};

/// The frames' prefix product of transports, a quaternion (w, v) a sample, in two copies.
struct FrameScan {
  float* w[2];
  Vec3* v[2];
};

// The brush stage's backend drivers (brush_impl.h), one list (core/exec/dispatch.h).
#define WB_BRUSH_KERNELS(X)                                                                                          \
  X(void, brush_integrate, (BristleState s, BristleRest r, BrushFrame f, BrushForces e, float beta_B, float damping, \
      float dt), (s, r, f, e, beta_B, damping, dt))                                                                  \
  X(void, brush_solve, (BristleState s, BristleRest r, BrushFrame f, SolidField solid, int iterations,               \
      float friction_it), (s, r, f, solid, iterations, friction_it))                                                 \
  X(void, brush_grid_keys, (BristleState s, float h, uint32_t mask, uint32_t* keys, uint32_t* ids),                  \
      (s, h, mask, keys, ids))                                                                                       \
  X(void, brush_grid_ranges, (const uint32_t* keys, int64_t n, uint32_t* cell_start, uint32_t* cell_end),            \
      (keys, n, cell_start, cell_end))                                                                               \
  X(void, brush_density_lambda, (BristleState s, MinDensityGrid g, float* lambda), (s, g, lambda))                   \
  X(void, brush_density_delta, (BristleState s, MinDensityGrid g, const float* lambda), (s, g, lambda))              \
  X(void, brush_density_apply, (BristleState s), (s))                                                                \
  X(void, brush_inextensible, (BristleState s, BristleRest r, BrushFrame f, SolidField solid), (s, r, f, solid))     \
  X(void, brush_velocities, (BristleState s, BrushFrame f, SolidField solid, float dt), (s, f, solid, dt))           \
  X(void, brush_restore, (BristleState s, BrushFrame f, int64_t* counts), (s, f, counts))                            \
  X(void, brush_place, (BristleState s, BristleRest r, BrushFrame f), (s, r, f))                                     \
  X(void, brush_stretch_and_z, (BristleState s, BristleRest r, float* stretch, float* z), (s, r, stretch, z))        \
  X(void, samples_spline, (BristleState s, SampleView sv, SamplePrev prev, SolidField solid), (s, sv, prev, solid))  \
  X(void, samples_frames, (SampleView sv, BrushFrame f, FrameScan scan), (sv, f, scan))                              \
  X(void, samples_motion, (SampleView sv, SamplePrev prev, float dt, int history), (sv, prev, dt, history))          \
  X(void, samples_z, (SampleView sv, float* z), (sv, z))                                                             \
  X(void, samples_rasterize, (SampleView sv, float radius, Int3 origin, Int3 dims, float* psi, float* vx, float* vy, \
      float* vz, TouchList cells), (sv, radius, origin, dims, psi, vx, vy, vz, cells))                               \
  X(void, samples_rasterize_finish, (int64_t n, float* psi, float* vx, float* vy, float* vz, TouchList cells),       \
      (n, psi, vx, vy, vz, cells))                                                                                   \
  X(void, samples_raster_clear, (int64_t n, float* psi, float* vx, float* vy, float* vz, TouchList cells),           \
      (n, psi, vx, vy, vz, cells))                                                                                   \
  X(void, samples_contact_keys, (SampleView sv, SolidField solid, float contact_height, int32_t* trace, int trace_w, \
      int trace_h, int ox, int oy, uint32_t* keys, uint32_t* vals),                                                  \
      (sv, solid, contact_height, trace, trace_w, trace_h, ox, oy, keys, vals))                                      \
  X(void, count_distinct_flags, (const uint32_t* keys, int64_t n, uint32_t sentinel, float* flags),                  \
      (keys, n, sentinel, flags))
WB_DECLARE_KERNELS(WB_BRUSH_KERNELS)

}  // namespace wb
