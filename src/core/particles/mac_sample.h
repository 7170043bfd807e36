// Trilinear sampling of a staggered (MAC) velocity field at a point (paper §4.3, Eq. 11
// reads u and u-bar at particle positions). Layout as the grid stage: positions in window
// cells, cell (i,j,k) spans [i,i+1) x [j,j+1) x [k,k+1); u(i,j,k) sits on the face at
// (i, j+1/2, k+1/2), v(i,j,k) at (i+1/2, j, k+1/2), w(i,j,k) at (i+1/2, j+1/2, k).
// u: (nx+1) x ny x nz, v: nx x (ny+1) x nz, w: nx x ny x (nz+1), x fastest.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/math/trilinear.h"
#include "core/math/vec.h"

namespace wb {

/// A MAC velocity field on the window, by value: faces as above, origin = canvas cell of the
/// window's cell (0, 0, 0), so a particle at canvas position p is at q = p - origin.
struct MacView {
  const float* u;
  const float* v;
  const float* w;
  int nx, ny, nz;
  int ox, oy, oz;
  WB_HD Vec3 local(Vec3 p) const { return Vec3(p.x - float(ox), p.y - float(oy), p.z - float(oz)); }
  WB_HD Vec3 sample(Vec3 p) const { return sample_mac(u, v, w, nx, ny, nz, local(p)); }
};

}  // namespace wb
