// Grid stage, advection (paper §4.2: semi-Lagrangian advection of all fields, Stam 1999).
// Trilinear sampling of cell-centred scalars and of the staggered velocity, and the
// backtrace. Positions are in window cells; velocities in cells/s; dt in s.
#pragma once
#include <cstdint>

#include "core/grid/grid_fields.h"
#include "core/math/trilinear.h"
#include "core/math/vec.h"

namespace wb {

/// One MAC component c at point p (window cells): the lattice of component c is offset by
/// half a cell on the two other axes.
WB_HD WB_INLINE float sample_component(const float* f, const GridDims& d, int c, Vec3 p) {
  int ex, ey, ez;
  d.face_extent(c, ex, ey, ez);
  return sample_nodes(f, ex, ey, ez, c == 0 ? 0.f : 0.5f, c == 1 ? 0.f : 0.5f, c == 2 ? 0.f : 0.5f, p);
}

/// Trilinear sample of the staggered velocity at p (window cells), cells/s. Used by
/// advection and by the particles (FLIP/PIC, Eq. 11).
WB_HD WB_INLINE Vec3 sample_velocity(const GridView& g, Vec3 p) {
  return Vec3(sample_component(g.vel[0], g.d, 0, p), sample_component(g.vel[1], g.d, 1, p),
              sample_component(g.vel[2], g.d, 2, p));
}

/// Same from raw component pointers (advection reads a velocity copy).
WB_HD WB_INLINE Vec3 sample_velocity3(const float* u, const float* v, const float* w, const GridDims& d, Vec3 p) {
  return Vec3(sample_component(u, d, 0, p), sample_component(v, d, 1, p), sample_component(w, d, 2, p));
}

/// Semi-Lagrangian backtrace by the explicit midpoint rule (RK2): x - dt u(x - dt/2 u(x)).
/// The departure point is clamped into the window.
WB_HD WB_INLINE Vec3 backtrace(const float* u, const float* v, const float* w, const GridDims& d, Vec3 x, float dt) {
  const Vec3 v0 = sample_velocity3(u, v, w, d, x);
  const Vec3 mid = x - v0 * (0.5f * dt);
  const Vec3 v1 = sample_velocity3(u, v, w, d, mid);
  Vec3 p = x - v1 * dt;
  p.x = clampf(p.x, 0.5f, float(d.nx) - 0.5f);
  p.y = clampf(p.y, 0.5f, float(d.ny) - 0.5f);
  p.z = clampf(p.z, 0.5f, float(d.nz) - 0.5f);
  return p;
}

/// Trilinear weights of the 8 cell centres around p (cell-centred lattice), with the
/// solid cells left out and the rest renormalised, so that advection never copies
/// dried paint into moving cells. Returns false when all 8 are solid.
struct CellStencil {
  int64_t idx[8];
  float wgt[8];
};
WB_HD WB_INLINE bool cell_stencil_fluid(const GridDims& d, const uint8_t* cls, Vec3 p, CellStencil& s) {
  const Stencil1 sx = stencil1(p.x, 0.5f, d.nx), sy = stencil1(p.y, 0.5f, d.ny), sz = stencil1(p.z, 0.5f, d.nz);
  const int i0 = sx.i0, i1 = sx.i1, j0 = sy.i0, j1 = sy.i1, k0 = sz.i0, k1 = sz.i1;
  const float fx = sx.w1, fy = sy.w1, fz = sz.w1;
  float total = 0.f;
  for (int n = 0; n < 8; ++n) {
    const int i = (n & 1) ? i1 : i0, j = (n & 2) ? j1 : j0, k = (n & 4) ? k1 : k0;
    const float wx = (n & 1) ? fx : 1.f - fx, wy = (n & 2) ? fy : 1.f - fy, wz = (n & 4) ? fz : 1.f - fz;
    const int64_t c = d.cell(i, j, k);
    const float wgt = cls[c] == kCellSolid ? 0.f : wx * wy * wz;
    s.idx[n] = c;
    s.wgt[n] = wgt;
    total += wgt;
  }
  if (total <= 1e-12f) return false;
  const float inv = 1.f / total;
  for (int n = 0; n < 8; ++n) s.wgt[n] *= inv;
  return true;
}

WB_HD WB_INLINE float apply_stencil(const CellStencil& s, const float* f) {
  float acc = 0.f;
  for (int n = 0; n < 8; ++n) acc += s.wgt[n] * f[s.idx[n]];
  return acc;
}

/// Position of face (i,j,k) of component c, window cells.
WB_HD WB_INLINE Vec3 face_position(int c, int i, int j, int k) {
  return Vec3(c == 0 ? float(i) : float(i) + 0.5f, c == 1 ? float(j) : float(j) + 0.5f,
              c == 2 ? float(k) : float(k) + 0.5f);
}

}  // namespace wb
