// Grid stage, advection (paper §4.2: semi-Lagrangian advection of all fields, Stam 1999).
// Trilinear sampling of cell-centred scalars and of the staggered velocity, and the
// backtrace. Positions are in window cells; velocities in cells/s; dt in s.
#pragma once
#include <cstdint>

#include "core/grid/grid_fields.h"
#include "core/math/vec.h"

namespace wb {

WB_HD WB_INLINE int floor_to_int(float x) {
  const int i = int(x);
  return (x < float(i)) ? i - 1 : i;
}

/// Trilinear interpolation of a lattice of ex x ey x ez values whose node (i,j,k) sits at
/// (i,j,k) + offset; the sample point is clamped into the lattice.
WB_HD WB_INLINE float sample_lattice(const float* f, int ex, int ey, int ez, float gx, float gy, float gz) {
  gx = clampf(gx, 0.f, float(ex - 1));
  gy = clampf(gy, 0.f, float(ey - 1));
  gz = clampf(gz, 0.f, float(ez - 1));
  const int i0 = clampi(floor_to_int(gx), 0, ex - 1), j0 = clampi(floor_to_int(gy), 0, ey - 1),
            k0 = clampi(floor_to_int(gz), 0, ez - 1);
  const int i1 = i0 + 1 < ex ? i0 + 1 : i0, j1 = j0 + 1 < ey ? j0 + 1 : j0, k1 = k0 + 1 < ez ? k0 + 1 : k0;
  const float fx = gx - float(i0), fy = gy - float(j0), fz = gz - float(k0);
  auto at = [&](int i, int j, int k) { return f[(int64_t(k) * ey + j) * ex + i]; };
  const float c00 = at(i0, j0, k0) * (1.f - fx) + at(i1, j0, k0) * fx;
  const float c10 = at(i0, j1, k0) * (1.f - fx) + at(i1, j1, k0) * fx;
  const float c01 = at(i0, j0, k1) * (1.f - fx) + at(i1, j0, k1) * fx;
  const float c11 = at(i0, j1, k1) * (1.f - fx) + at(i1, j1, k1) * fx;
  return (c00 * (1.f - fy) + c10 * fy) * (1.f - fz) + (c01 * (1.f - fy) + c11 * fy) * fz;
}

/// One MAC component c at point p (window cells): the lattice of component c is offset by
/// half a cell on the two other axes.
WB_HD WB_INLINE float sample_component(const float* f, const GridDims& d, int c, Vec3 p) {
  int ex, ey, ez;
  d.face_extent(c, ex, ey, ez);
  return sample_lattice(f, ex, ey, ez, c == 0 ? p.x : p.x - 0.5f, c == 1 ? p.y : p.y - 0.5f,
                        c == 2 ? p.z : p.z - 0.5f);
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
  const float gx = clampf(p.x - 0.5f, 0.f, float(d.nx - 1)), gy = clampf(p.y - 0.5f, 0.f, float(d.ny - 1)),
              gz = clampf(p.z - 0.5f, 0.f, float(d.nz - 1));
  const int i0 = clampi(floor_to_int(gx), 0, d.nx - 1), j0 = clampi(floor_to_int(gy), 0, d.ny - 1),
            k0 = clampi(floor_to_int(gz), 0, d.nz - 1);
  const int i1 = i0 + 1 < d.nx ? i0 + 1 : i0, j1 = j0 + 1 < d.ny ? j0 + 1 : j0, k1 = k0 + 1 < d.nz ? k0 + 1 : k0;
  const float fx = gx - float(i0), fy = gy - float(j0), fz = gz - float(k0);
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
