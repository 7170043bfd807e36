// Particle <-> window grid (paper §4.3, Eq. 11; DESIGN steps 5 and 7): rasterise the
// particles' mass and momentum onto the window (joint fields), and the mixed FLIP/PIC
// velocity update from the fields before and after projection.
#pragma once
#include <cstdint>

#include "core/exec/atomics.h"
#include "core/exec/hd.h"
#include "core/exec/touch_list.h"
#include "core/math/vec.h"
#include "core/particles/mac_sample.h"

namespace wb {

/// Where particles are rasterised, by value. Accumulates (callers zero it). cell is
/// cell-centred (index (k*ny + j)*nx + i): first the mass (kg), second the mass times the oil
/// fraction. face[c] is on the MAC faces of component c (layout of mac_sample.h): first the
/// face's mass weight (kg), second the momentum (kg cells/s), so that the face velocity is
/// second / first. Each pair is added by one atomic (atomics.h).
struct ParticleRasterView {
  FloatPair* cell;
  FloatPair* face[3];  ///< all null: the cells alone
  int nx, ny, nz;
  int ox, oy, oz;  ///< canvas cell of the window's cell (0, 0, 0)
  /// Where on: the cells and faces the raster reaches are listed (the passes after it visit
  /// those, and the fields go back to zero through them, Simulator::clear_raster).
  TouchList cell_list{}, face_list[3]{};
};

/// Splats pairs (a, b) trilinearly onto a node grid of ex x ey x ez nodes at offsets (ox, oy, oz):
/// the cloud-in-cell weights of sample_nodes, so splat and sample are adjoint, clamped at the
/// edges like sampling, so the weights always sum to one and nothing is lost. The splats of a
/// run of consecutive particles whose stencils share their nodes (the same lower corner) are
/// summed before they are added to the grid: a particle's eight atomic adds become one set a
/// run. Particles sorted by half cell (ParticleStore::sort_by_cell) come in such runs.
struct SplatRun {
  int64_t base = -1;  ///< node of the run's lower corner, -1: no run open
  int64_t node[8];
  FloatPair sum[8];
  /// Adds the open run's sums to f (nodes whose sums are both zero are skipped), listing the
  /// nodes it adds to where `list` is on, and closes it.
  WB_HD void flush(FloatPair* f, const TouchList& list) {
    if (base < 0) return;
    for (int n = 0; n < 8; ++n)
      if (sum[n].first != 0.f || sum[n].second != 0.f) {
        atomic_add(&f[node[n]], sum[n].first, sum[n].second);
        if (list.on()) list.touch(node[n]);
      }
    base = -1;
  }
  /// The weights of the pair (a, b) at the node stencil of sx, sy, sz on a grid of ex x ey nodes a
  /// layer, into the run (flushed first if the stencil's corner is another).
  WB_HD void add(FloatPair* f, const TouchList& list, int ex, int ey, const Stencil1& sx, const Stencil1& sy,
                 const Stencil1& sz, float a, float b) {
    const int64_t corner = (int64_t(sz.i0) * ey + sy.i0) * ex + sx.i0;
    if (corner != base) {
      flush(f, list);
      base = corner;
      const int ix[2] = {sx.i0, sx.i1}, iy[2] = {sy.i0, sy.i1}, iz[2] = {sz.i0, sz.i1};
      for (int n = 0; n < 8; ++n) {
        node[n] = (int64_t(iz[n >> 2]) * ey + iy[(n >> 1) & 1]) * ex + ix[n & 1];
        sum[n] = FloatPair{0.f, 0.f};
      }
    }
    const float wx[2] = {1.f - sx.w1, sx.w1}, wy[2] = {1.f - sy.w1, sy.w1}, wz[2] = {1.f - sz.w1, sz.w1};
    for (int n = 0; n < 8; ++n) {
      const float wgt = wx[n & 1] * wy[(n >> 1) & 1] * wz[n >> 2];
      sum[n].first += a * wgt;
      sum[n].second += b * wgt;
    }
  }
};

/// True when q (window cells) lies inside the window; particles outside are not rasterised.
WB_HD WB_INLINE bool inside_window(Vec3 q, int nx, int ny, int nz) {
  return q.x >= 0.f && q.y >= 0.f && q.z >= 0.f && q.x < float(nx) && q.y < float(ny) && q.z < float(nz);
}

/// Rasterises particles [k0, k1) of p, a run at a time on each grid (SplatRun): mass and oil onto
/// the cell centres, weight m and momentum m v_c onto the faces of each component c (the cells
/// alone when g.face[0] is null). A particle's axes are placed once for the four grids
/// (axis_stencils). Particles outside the window are skipped.
WB_HD WB_INLINE void rasterise_particles(const ParticleRasterView& g, const Vec3* x, const Vec3* v, const float* m,
                                         const float* oil, int64_t k0, int64_t k1) {
  const Vec3 o(float(g.ox), float(g.oy), float(g.oz));
  const bool faces = g.face[0] != nullptr;
  SplatRun cell, face[3];
  for (int64_t k = k0; k < k1; ++k) {
    const Vec3 q = x[k] - o;
    if (!inside_window(q, g.nx, g.ny, g.nz)) continue;
    const float mk = m[k];
    if (!faces) {
      cell.add(g.cell, g.cell_list, g.nx, g.ny, stencil1(q.x, 0.5f, g.nx), stencil1(q.y, 0.5f, g.ny),
               stencil1(q.z, 0.5f, g.nz), mk, mk * oil[k]);
      continue;
    }
    const AxisStencils sx = axis_stencils(q.x, g.nx), sy = axis_stencils(q.y, g.ny), sz = axis_stencils(q.z, g.nz);
    const Vec3 vk = v[k];
    cell.add(g.cell, g.cell_list, g.nx, g.ny, sx.centre, sy.centre, sz.centre, mk, mk * oil[k]);
    face[0].add(g.face[0], g.face_list[0], g.nx + 1, g.ny, sx.face, sy.centre, sz.centre, mk, mk * vk.x);
    face[1].add(g.face[1], g.face_list[1], g.nx, g.ny + 1, sx.centre, sy.face, sz.centre, mk, mk * vk.y);
    face[2].add(g.face[2], g.face_list[2], g.nx, g.ny, sx.centre, sy.centre, sz.face, mk, mk * vk.z);
  }
  cell.flush(g.cell, g.cell_list);
  for (int c = 0; c < 3 && faces; ++c) face[c].flush(g.face[c], g.face_list[c]);
}

/// Face velocity from a rasterised face: momentum / weight where the face got mass, else `empty`.
WB_HD WB_INLINE float face_velocity(FloatPair face, float empty) {
  return face.first > 0.f ? face.second / face.first : empty;
}

/// Eq. 11: v_new = gamma u_bar(p) + (1 - gamma) (v + u_bar(p) - u(p)), u and u_bar the joint
/// field before and after projection sampled at the particle (PIC weight gamma).
WB_HD WB_INLINE Vec3 flip_pic_velocity(Vec3 v, Vec3 u_before, Vec3 u_after, float gamma) {
  return u_after * gamma + (v + u_after - u_before) * (1.f - gamma);
}

}  // namespace wb
