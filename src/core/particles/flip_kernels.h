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

/// Where particles are rasterised, by value. Accumulates (callers zero it, or add the
/// particles onto the grid liquid already there). mass is cell-centred (kg, index
/// (k*ny + j)*nx + i); mom[c] and weight[c] are on the MAC faces of component c (layout of
/// mac_sample.h): momentum in kg cells/s and the mass weight of the face in kg, so that
/// the face velocity is mom / weight.
struct ParticleRasterView {
  float* mass;
  float* mom[3];
  float* weight[3];
  int nx, ny, nz;
  int ox, oy, oz;  ///< canvas cell of the window's cell (0, 0, 0)
  float* oil = nullptr;  ///< cell-centred, mass times oil fraction (nullable)
};

/// Splats `value` trilinearly onto a node grid of ex x ey x ez nodes at offsets (ox, oy, oz):
/// the cloud-in-cell weights of sample_nodes, so splat and sample are adjoint. Clamped at the
/// edges like sampling, so the weights always sum to one and nothing is lost.
WB_HD WB_INLINE void splat_nodes(float* f, int ex, int ey, int ez, float ox, float oy, float oz, Vec3 q, float value) {
  const Stencil1 sx = stencil1(q.x, ox, ex), sy = stencil1(q.y, oy, ey), sz = stencil1(q.z, oz, ez);
  const float wx[2] = {1.f - sx.w1, sx.w1}, wy[2] = {1.f - sy.w1, sy.w1}, wz[2] = {1.f - sz.w1, sz.w1};
  const int ix[2] = {sx.i0, sx.i1}, iy[2] = {sy.i0, sy.i1}, iz[2] = {sz.i0, sz.i1};
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const float wgt = wx[a] * wy[b] * wz[c];
        if (wgt != 0.f) atomic_add(&f[(int64_t(iz[c]) * ey + iy[b]) * ex + ix[a]], value * wgt);
      }
}

/// True when q (window cells) lies inside the window; particles outside are not rasterised.
WB_HD WB_INLINE bool inside_window(Vec3 q, int nx, int ny, int nz) {
  return q.x >= 0.f && q.y >= 0.f && q.z >= 0.f && q.x < float(nx) && q.y < float(ny) && q.z < float(nz);
}

/// Rasterises one particle of mass m and velocity vel at canvas position p: mass onto the
/// cell centres, momentum m v_c and weight m onto the faces of each component c (mass only
/// when g.mom[0] is null).
WB_HD WB_INLINE void rasterise_particle(const ParticleRasterView& g, Vec3 p, Vec3 vel, float m, float oil) {
  const Vec3 q(p.x - float(g.ox), p.y - float(g.oy), p.z - float(g.oz));
  if (!inside_window(q, g.nx, g.ny, g.nz)) return;
  splat_nodes(g.mass, g.nx, g.ny, g.nz, 0.5f, 0.5f, 0.5f, q, m);
  if (g.oil) splat_nodes(g.oil, g.nx, g.ny, g.nz, 0.5f, 0.5f, 0.5f, q, m * oil);
  if (g.mom[0] == nullptr) return;
  splat_nodes(g.mom[0], g.nx + 1, g.ny, g.nz, 0.f, 0.5f, 0.5f, q, m * vel.x);
  splat_nodes(g.weight[0], g.nx + 1, g.ny, g.nz, 0.f, 0.5f, 0.5f, q, m);
  splat_nodes(g.mom[1], g.nx, g.ny + 1, g.nz, 0.5f, 0.f, 0.5f, q, m * vel.y);
  splat_nodes(g.weight[1], g.nx, g.ny + 1, g.nz, 0.5f, 0.f, 0.5f, q, m);
  splat_nodes(g.mom[2], g.nx, g.ny, g.nz + 1, 0.5f, 0.5f, 0.f, q, m * vel.z);
  splat_nodes(g.weight[2], g.nx, g.ny, g.nz + 1, 0.5f, 0.5f, 0.f, q, m);
}

/// Face velocity from rasterised momentum: mom / weight where the face got mass, else `empty`.
WB_HD WB_INLINE float face_velocity(float mom, float weight, float empty) { return weight > 0.f ? mom / weight : empty; }

/// Eq. 11: v_new = gamma u_bar(p) + (1 - gamma) (v + u_bar(p) - u(p)), u and u_bar the joint
/// field before and after projection sampled at the particle (PIC weight gamma).
WB_HD WB_INLINE Vec3 flip_pic_velocity(Vec3 v, Vec3 u_before, Vec3 u_after, float gamma) {
  return u_after * gamma + (v + u_after - u_before) * (1.f - gamma);
}

}  // namespace wb
