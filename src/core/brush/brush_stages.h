// Brush stage drivers (paper §4.1), declared for both backends. Defined once in
// brush_impl.h and compiled twice (brush_cpu.cpp, brush_cuda.cu); brush.cpp is the one
// dispatcher. Every function is one or a few parallel_for launches over device pointers.
#pragma once
#include <cstdint>

#include "core/brush/bristle_fields.h"
#include "core/brush/brush_views.h"
#include "core/canvas/window.h"

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

#define WB_BRUSH_STAGE_DECLS                                                                                      \
  void brush_integrate(BristleState s, BristleRest r, BrushFrame f, BrushForces e, float beta_B, float damping,    \
                       float dt);                                                                                  \
  void brush_solve(BristleState s, BristleRest r, BrushFrame f, SolidField solid, int iterations, float friction_it); \
  void brush_grid_keys(BristleState s, float h, uint32_t mask, uint32_t* keys, uint32_t* ids);                      \
  void brush_grid_ranges(const uint32_t* keys, int64_t n, uint32_t* cell_start, uint32_t* cell_end);               \
  void brush_density_lambda(BristleState s, MinDensityGrid g, float* lambda);                                      \
  void brush_density_delta(BristleState s, MinDensityGrid g, const float* lambda);                                 \
  void brush_density_apply(BristleState s);                                                                        \
  void brush_inextensible(BristleState s, BristleRest r, BrushFrame f, SolidField solid);                         \
  void brush_velocities(BristleState s, BrushFrame f, SolidField solid, float dt);                                \
  void brush_restore(BristleState s, BrushFrame f, int64_t* counts);                                              \
  void brush_place(BristleState s, BristleRest r, BrushFrame f);                                                   \
  void brush_stretch_and_z(BristleState s, BristleRest r, float* stretch, float* z);                              \
  void samples_spline(BristleState s, SampleView sv, SamplePrev prev, SolidField solid);                           \
  void samples_frames(SampleView sv, BrushFrame f, FrameScan scan);                                                \
  void samples_motion(SampleView sv, SamplePrev prev, float dt, int history);                                     \
  void samples_z(SampleView sv, float* z);                                                                         \
  void samples_rasterize(SampleView sv, float radius, Int3 origin, Int3 dims, float* psi, float* vx, float* vy,    \
                         float* vz);                                                                               \
  void samples_rasterize_finish(int64_t cells, float* psi, float* vx, float* vy, float* vz);                       \
  void samples_contact_keys(SampleView sv, SolidField solid, float contact_height, int32_t* trace, int trace_w,    \
                            int trace_h, int ox, int oy, uint32_t* keys, uint32_t* vals);                          \
  void count_distinct_flags(const uint32_t* keys, int64_t n, uint32_t sentinel, float* flags);

namespace cpu {
WB_BRUSH_STAGE_DECLS
}  // namespace cpu
namespace cuda {
WB_BRUSH_STAGE_DECLS
}  // namespace cuda

}  // namespace wb
