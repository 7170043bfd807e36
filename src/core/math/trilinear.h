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

/// Trilinear sample of one node grid of ex x ey x ez nodes at offsets (ox, oy, oz) cells.
WB_HD WB_INLINE float sample_nodes(const float* f, int ex, int ey, int ez, float ox, float oy, float oz, Vec3 q) {
  const Stencil1 sx = stencil1(q.x, ox, ex), sy = stencil1(q.y, oy, ey), sz = stencil1(q.z, oz, ez);
  auto at = [&](int i, int j, int k) { return f[(int64_t(k) * ey + j) * ex + i]; };
  const float c00 = at(sx.i0, sy.i0, sz.i0) * (1.f - sx.w1) + at(sx.i1, sy.i0, sz.i0) * sx.w1;
  const float c10 = at(sx.i0, sy.i1, sz.i0) * (1.f - sx.w1) + at(sx.i1, sy.i1, sz.i0) * sx.w1;
  const float c01 = at(sx.i0, sy.i0, sz.i1) * (1.f - sx.w1) + at(sx.i1, sy.i0, sz.i1) * sx.w1;
  const float c11 = at(sx.i0, sy.i1, sz.i1) * (1.f - sx.w1) + at(sx.i1, sy.i1, sz.i1) * sx.w1;
  const float c0 = c00 * (1.f - sy.w1) + c10 * sy.w1;
  const float c1 = c01 * (1.f - sy.w1) + c11 * sy.w1;
  return c0 * (1.f - sz.w1) + c1 * sz.w1;
}

/// Trilinear samples of two fields on the same node grid at q, the stencil worked out once (each
/// value as sample_nodes gives it).
WB_HD WB_INLINE void sample_nodes_pair(const float* f, const float* g, int ex, int ey, int ez, float ox, float oy,
                                       float oz, Vec3 q, float& fq, float& gq) {
  const Stencil1 sx = stencil1(q.x, ox, ex), sy = stencil1(q.y, oy, ey), sz = stencil1(q.z, oz, ez);
  const int64_t n[8] = {(int64_t(sz.i0) * ey + sy.i0) * ex + sx.i0, (int64_t(sz.i0) * ey + sy.i0) * ex + sx.i1,
                        (int64_t(sz.i0) * ey + sy.i1) * ex + sx.i0, (int64_t(sz.i0) * ey + sy.i1) * ex + sx.i1,
                        (int64_t(sz.i1) * ey + sy.i0) * ex + sx.i0, (int64_t(sz.i1) * ey + sy.i0) * ex + sx.i1,
                        (int64_t(sz.i1) * ey + sy.i1) * ex + sx.i0, (int64_t(sz.i1) * ey + sy.i1) * ex + sx.i1};
  auto blend = [&](const float* h) {
    const float c00 = h[n[0]] * (1.f - sx.w1) + h[n[1]] * sx.w1;
    const float c10 = h[n[2]] * (1.f - sx.w1) + h[n[3]] * sx.w1;
    const float c01 = h[n[4]] * (1.f - sx.w1) + h[n[5]] * sx.w1;
    const float c11 = h[n[6]] * (1.f - sx.w1) + h[n[7]] * sx.w1;
    const float c0 = c00 * (1.f - sy.w1) + c10 * sy.w1;
    const float c1 = c01 * (1.f - sy.w1) + c11 * sy.w1;
    return c0 * (1.f - sz.w1) + c1 * sz.w1;
  };
  fq = blend(f);
  gq = blend(g);
}

/// Velocity of the MAC field (u, v, w) at q (window cells): each component trilinear on its
/// own faces, clamped at the window's edges. u(i,j,k) sits on the face at (i, j+1/2, k+1/2),
/// v(i,j,k) at (i+1/2, j, k+1/2), w(i,j,k) at (i+1/2, j+1/2, k); u: (nx+1) x ny x nz,
/// v: nx x (ny+1) x nz, w: nx x ny x (nz+1), x fastest.
WB_HD WB_INLINE Vec3 sample_mac(const float* u, const float* v, const float* w, int nx, int ny, int nz, Vec3 q) {
  return Vec3(sample_nodes(u, nx + 1, ny, nz, 0.f, 0.5f, 0.5f, q), sample_nodes(v, nx, ny + 1, nz, 0.5f, 0.f, 0.5f, q),
              sample_nodes(w, nx, ny, nz + 1, 0.5f, 0.5f, 0.f, q));
}

}  // namespace wb
