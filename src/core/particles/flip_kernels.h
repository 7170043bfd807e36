// Particle <-> window grid (paper §4.3, Eq. 11; DESIGN steps 5 and 7): rasterise the
// particles' mass and momentum onto the window (joint fields), and the mixed FLIP/PIC
// velocity update from the fields before and after projection.
#pragma once
#include <cstdint>

#include "core/exec/atomics.h"
#include "core/exec/hd.h"
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
};

/// Splats the pair (a, b) trilinearly onto a node grid of ex x ey x ez nodes at offsets (ox, oy, oz):
/// the cloud-in-cell weights of sample_nodes, so splat and sample are adjoint. Clamped at the
/// edges like sampling, so the weights always sum to one and nothing is lost.
WB_HD WB_INLINE void splat_nodes(FloatPair* f, int ex, int ey, int ez, float ox, float oy, float oz, Vec3 q, float a,
                                  float b) {
  const Stencil1 sx = stencil1(q.x, ox, ex), sy = stencil1(q.y, oy, ey), sz = stencil1(q.z, oz, ez);
  const float wx[2] = {1.f - sx.w1, sx.w1}, wy[2] = {1.f - sy.w1, sy.w1}, wz[2] = {1.f - sz.w1, sz.w1};
  const int ix[2] = {sx.i0, sx.i1}, iy[2] = {sy.i0, sy.i1}, iz[2] = {sz.i0, sz.i1};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const float wgt = wx[i] * wy[j] * wz[k];
        if (wgt != 0.f) atomic_add(&f[(int64_t(iz[k]) * ey + iy[j]) * ex + ix[i]], a * wgt, b * wgt);
      }
}

/// True when q (window cells) lies inside the window; particles outside are not rasterised.
WB_HD WB_INLINE bool inside_window(Vec3 q, int nx, int ny, int nz) {
  return q.x >= 0.f && q.y >= 0.f && q.z >= 0.f && q.x < float(nx) && q.y < float(ny) && q.z < float(nz);
}

/// Rasterises one particle of mass m and velocity vel at canvas position p: mass and oil onto
/// the cell centres, weight m and momentum m v_c onto the faces of each component c (the cells
/// alone when g.face[0] is null).
WB_HD WB_INLINE void rasterise_particle(const ParticleRasterView& g, Vec3 p, Vec3 vel, float m, float oil) {
  const Vec3 q(p.x - float(g.ox), p.y - float(g.oy), p.z - float(g.oz));
  if (!inside_window(q, g.nx, g.ny, g.nz)) return;
  splat_nodes(g.cell, g.nx, g.ny, g.nz, 0.5f, 0.5f, 0.5f, q, m, m * oil);
  if (g.face[0] == nullptr) return;
  splat_nodes(g.face[0], g.nx + 1, g.ny, g.nz, 0.f, 0.5f, 0.5f, q, m, m * vel.x);
  splat_nodes(g.face[1], g.nx, g.ny + 1, g.nz, 0.5f, 0.f, 0.5f, q, m, m * vel.y);
  splat_nodes(g.face[2], g.nx, g.ny, g.nz + 1, 0.5f, 0.5f, 0.f, q, m, m * vel.z);
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
