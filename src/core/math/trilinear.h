// Trilinear sampling of a lattice of nodes with constant extension past its ends: the one
// interpolation the grid's advection (cell-centred fields, MAC faces) and the particles
// (Eq. 11 reads u at their positions; the rasteriser splats with the adjoint weights) share.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// Trilinear stencil along one axis for nodes at (i + off), i in [0, n): the two node
/// indices and the weight of the upper one. Outside the node range the stencil clamps to the
/// end node (constant extension), so the two weights always sum to one.
struct Stencil1 {
  int i0, i1;
  float w1;
};
WB_HD WB_INLINE Stencil1 stencil1(float q, float off, int n) {
  const float s = q - off;
  const float fl = floorf(s);
  int i0 = int(fl);
  float w1 = s - fl;
  if (i0 < 0) {
    i0 = 0;
    w1 = 0.f;
  } else if (i0 >= n - 1) {
    i0 = n - 1;
    w1 = 0.f;
  }
  return Stencil1{i0, i0 + 1 < n ? i0 + 1 : n - 1, w1};
}

/// The eight nodes around q on a node grid of ex x ey x ez nodes at offsets (ox, oy, oz) cells and
/// their weights, worked out once for as many fields on that grid as are sampled at q.
struct NodeStencil {
  int64_t n[8];  ///< (i, j, k) of the lower corner plus (n & 1, (n >> 1) & 1, n >> 2), x fastest
  float wx, wy, wz;
  WB_HD float of(const float* f) const {
    const float c00 = f[n[0]] * (1.f - wx) + f[n[1]] * wx;
    const float c10 = f[n[2]] * (1.f - wx) + f[n[3]] * wx;
    const float c01 = f[n[4]] * (1.f - wx) + f[n[5]] * wx;
    const float c11 = f[n[6]] * (1.f - wx) + f[n[7]] * wx;
    const float c0 = c00 * (1.f - wy) + c10 * wy;
    const float c1 = c01 * (1.f - wy) + c11 * wy;
    return c0 * (1.f - wz) + c1 * wz;
  }
};
/// A node grid's stencil at q from its three axes' stencils (ex x ey nodes a layer)...
WB_HD WB_INLINE NodeStencil node_stencil(int ex, int ey, const Stencil1& sx, const Stencil1& sy, const Stencil1& sz) {
  NodeStencil s;
  const int ix[2] = {sx.i0, sx.i1}, iy[2] = {sy.i0, sy.i1}, iz[2] = {sz.i0, sz.i1};
  for (int c = 0; c < 8; ++c) s.n[c] = (int64_t(iz[c >> 2]) * ey + iy[(c >> 1) & 1]) * ex + ix[c & 1];
  s.wx = sx.w1, s.wy = sy.w1, s.wz = sz.w1;
  return s;
}
/// ... or from q on a grid of ex x ey x ez nodes at offsets (ox, oy, oz) cells.
WB_HD WB_INLINE NodeStencil node_stencil(int ex, int ey, int ez, float ox, float oy, float oz, Vec3 q) {
  return node_stencil(ex, ey, stencil1(q.x, ox, ex), stencil1(q.y, oy, ey), stencil1(q.z, oz, ez));
}

/// Along one axis of a window of n cells, the stencils of the cells' centres (n nodes at 1/2)
/// and of the faces across the axis (n + 1 nodes at 0): the two node grids a window has on it.
struct AxisStencils {
  Stencil1 centre, face;
};
WB_HD WB_INLINE AxisStencils axis_stencils(float q, int n) { return {stencil1(q, 0.5f, n), stencil1(q, 0.f, n + 1)}; }

/// Trilinear sample of one node grid of ex x ey x ez nodes at offsets (ox, oy, oz) cells.
WB_HD WB_INLINE float sample_nodes(const float* f, int ex, int ey, int ez, float ox, float oy, float oz, Vec3 q) {
  return node_stencil(ex, ey, ez, ox, oy, oz, q).of(f);
}

/// The three stencils of a MAC field at q (window cells): each component trilinear on its own
/// faces, clamped at the window's edges. u(i,j,k) sits on the face at (i, j+1/2, k+1/2),
/// v(i,j,k) at (i+1/2, j, k+1/2), w(i,j,k) at (i+1/2, j+1/2, k); u: (nx+1) x ny x nz,
/// v: nx x (ny+1) x nz, w: nx x ny x (nz+1), x fastest.
struct MacStencil {
  NodeStencil u, v, w;
  WB_HD Vec3 of(const float* fu, const float* fv, const float* fw) const { return Vec3(u.of(fu), v.of(fv), w.of(fw)); }
};
WB_HD WB_INLINE MacStencil mac_stencil(int nx, int ny, int nz, Vec3 q) {
  const AxisStencils x = axis_stencils(q.x, nx), y = axis_stencils(q.y, ny), z = axis_stencils(q.z, nz);
  return MacStencil{node_stencil(nx + 1, ny, x.face, y.centre, z.centre), node_stencil(nx, ny + 1, x.centre, y.face, z.centre),
                    node_stencil(nx, ny, x.centre, y.centre, z.face)};
}

/// Velocity of the MAC field (u, v, w) at q (window cells) (mac_stencil).
WB_HD WB_INLINE Vec3 sample_mac(const float* u, const float* v, const float* w, int nx, int ny, int nz, Vec3 q) {
  return mac_stencil(nx, ny, nz, q).of(u, v, w);
}

}  // namespace wb
