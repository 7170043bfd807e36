// Grid stage, viscosity (paper §4.2; DESIGN step 6 "viscosity from oil density"):
// backward-Euler diffusion of each MAC component, (1 - nu dt Laplacian) u = u_old,
// solved by Jacobi sweeps. Each sweep is a convex combination of u_old and neighbours,
// so it is stable for any nu dt (the thickest paint at dt = 1/60 s included).
#pragma once
#include <cmath>

#include "core/grid/grid_fields.h"
#include "core/grid/project_kernels.h"
#include "core/math/vec.h"

namespace wb {

/// nu(oil) = nu_thick (nu_thin / nu_thick)^oil, cells^2/s: more oil, thinner paint.
WB_HD WB_INLINE float viscosity_from_oil(float oil, float nu_thick, float nu_thin) {
  oil = clampf(oil, 0.f, 1.f);
  if (nu_thick <= 0.f || nu_thin <= 0.f) return nu_thick + (nu_thin - nu_thick) * oil;
  return nu_thick * powf(nu_thin / nu_thick, oil);
}

/// Mean oil of the cells a face separates (those in the window).
WB_HD WB_INLINE float face_oil(const GridDims& d, const float* oil, int c, int i, int j, int k) {
  int64_t a, b;
  bool ha, hb;
  face_cells(d, c, i, j, k, a, b, ha, hb);
  if (ha && hb) return 0.5f * (oil[a] + oil[b]);
  return ha ? oil[a] : (hb ? oil[b] : 0.f);
}

/// One Jacobi sweep of backward Euler for a fluid face f:
/// u_f = (u_old_f + nu dt sum_n u_n) / (1 + nu dt N). Neighbours: fluid faces (current
/// iterate), closed faces (their solid velocity: no-slip on bristles and dried paint), the
/// canvas floor below the first layer (no-slip, 0). Faces open to air and the window's side
/// walls are left out (free slip).
WB_HD WB_INLINE float viscosity_jacobi_face(const GridView& g, const float* cur, const float* old, int c, int i, int j,
                                            int k, float nu_dt) {
  const GridDims& d = g.d;
  int ex, ey, ez;
  d.face_extent(c, ex, ey, ez);
  const int di[6] = {-1, 1, 0, 0, 0, 0}, dj[6] = {0, 0, -1, 1, 0, 0}, dk[6] = {0, 0, 0, 0, -1, 1};
  float acc = 0.f;
  int n = 0;
  for (int q = 0; q < 6; ++q) {
    const int ii = i + di[q], jj = j + dj[q], kk = k + dk[q];
    if (kk < 0) {  // below the first layer: the canvas floor
      ++n;
      continue;
    }
    if (ii < 0 || jj < 0 || ii >= ex || jj >= ey || kk >= ez) continue;
    const int64_t nf = d.fidx(c, ii, jj, kk);
    if (g.theta[c][nf] <= 0.f) {
      acc += g.solid_vel[c][nf];
      ++n;
    } else if (g.fluid[c][nf]) {
      acc += cur[nf];
      ++n;
    }
  }
  const int64_t f = d.fidx(c, i, j, k);
  return (old[f] + nu_dt * acc) / (1.f + nu_dt * float(n));
}

}  // namespace wb
