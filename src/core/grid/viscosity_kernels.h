// Grid stage, viscosity (paper §4.2; docs/GRID.md "Viscosity"): backward Euler of the
// variable-viscosity diffusion of each MAC component,
//   u - dt div(nu grad u) = u_old,   nu = mu(gamma_dot) / rho0 (rheology.h),
// on the faces that touch liquid, solved by Jacobi-preconditioned conjugate gradients to a
// stated tolerance (grid.cpp). The matrix is symmetric positive definite: the link between two
// fluid faces carries the harmonic mean of their viscosities (link_nu), the same from either side.
#pragma once
#include <cstdint>

#include "core/grid/grid_fields.h"
#include "core/grid/project_kernels.h"
#include "core/math/vec.h"

namespace wb {

/// Index of face (c, f) in the concatenated u | v | w list.
WB_HD WB_INLINE int64_t global_face(const GridDims& d, int c, int64_t f) {
  return f + (c >= 1 ? d.nu() : 0) + (c == 2 ? d.nv() : 0);
}

/// Visits the viscous couplings of fluid face (c,i,j,k) with its six same-component neighbours:
/// fluid(t) for a neighbouring fluid face (global index t), wall(u, s) for a no-slip neighbour of
/// velocity u and weight s (the canvas floor below the first layer, 0; a closed face, its solid
/// velocity: bristles and dried paint). Faces open to air and the window's side walls add nothing
/// (free slip). A face partly covered by bristles (open fraction theta < 1) is also coupled to
/// the bristles inside its own cell, with weight kPartialWall (1 - theta): the solid lies within
/// half a cell, so a face half covered couples to it like a wall neighbour. Without this term a
/// partly covered face moves independently of the bristles in it and a brush slides through stiff
/// paint instead of pushing it (docs/GRID.md "Viscosity").
constexpr float kPartialWall = 2.f;
template <class Fluid, class Wall>
WB_HD WB_INLINE void for_viscous_links(const GridView& g, int c, int i, int j, int k, Fluid&& fluid, Wall&& wall) {
  const GridDims& d = g.d;
  const int64_t self = d.fidx(c, i, j, k);
  const float theta = g.theta[c][self];
  if (theta < 1.f) wall(g.solid_vel[c][self], kPartialWall * (1.f - theta));
  int ex, ey, ez;
  d.face_extent(c, ex, ey, ez);
  const int di[6] = {-1, 1, 0, 0, 0, 0}, dj[6] = {0, 0, -1, 1, 0, 0}, dk[6] = {0, 0, 0, 0, -1, 1};
  for (int q = 0; q < 6; ++q) {
    const int ii = i + di[q], jj = j + dj[q], kk = k + dk[q];
    if (kk < 0) {
      wall(0.f, 1.f);
      continue;
    }
    if (ii < 0 || jj < 0 || ii >= ex || jj >= ey || kk >= ez) continue;
    const int64_t nf = d.fidx(c, ii, jj, kk);
    if (g.theta[c][nf] <= 0.f)
      wall(g.solid_vel[c][nf], 1.f);
    else if (g.fluid[c][nf])
      fluid(global_face(d, c, nf));
  }
}

/// nu dt of a face, cells^2: the mean apparent viscosity of the liquid cells it separates
/// (mu, Pa s) times nu_scale = dt / (rho0 h^2).
WB_HD WB_INLINE float face_nu_dt(const GridView& g, const float* mu, int c, int i, int j, int k, float nu_scale) {
  int64_t a, b;
  bool ha, hb;
  face_cells(g.d, c, i, j, k, a, b, ha, hb);
  const bool la = ha && g.cls[a] == kCellLiquid, lb = hb && g.cls[b] == kCellLiquid;
  const float m = la && lb ? 0.5f * (mu[a] + mu[b]) : (la ? mu[a] : (lb ? mu[b] : 0.f));
  return m * nu_scale;
}

/// Viscosity of the link between two faces: the harmonic mean, as for resistances in series. The
/// shear stress is continuous across an interface, so a soft layer on a stiff one shears in the
/// soft layer; the arithmetic mean would weld the soft paint to the stiff (a drop of oily paint on
/// a slope of stiff paint then never slides, docs/GRID.md).
WB_HD WB_INLINE float link_nu(float a, float b) { return (a + b) > 0.f ? 2.f * a * b / (a + b) : 0.f; }

/// Row of the system for list entry e (fluid face c,i,j,k): its fluid neighbours' entries
/// (nb[0..6), -1 where none), the diagonal 1 + sum of link weights and the right-hand side
/// u_old + sum over walls of weight * wall velocity. nu is compact (entry-indexed), idx maps a
/// global face to its entry.
WB_HD WB_INLINE void viscous_row(const GridView& g, const float* nu, const uint32_t* idx, int64_t e, int c, int i,
                                 int j, int k, float u_old, int32_t* nb, double& diag, double& rhs) {
  const float nf = nu[e];
  double dsum = 1.0, r = u_old;
  int q = 0;
  for_viscous_links(
      g, c, i, j, k,
      [&](int64_t t) {
        const uint32_t en = idx[t];
        nb[q++] = int32_t(en);
        dsum += double(link_nu(nf, nu[en]));
      },
      [&](float uw, float s) {
        dsum += double(s * nf);
        r += double(s * nf) * double(uw);
      });
  for (; q < 6; ++q) nb[q] = -1;
  diag = dsum;
  rhs = r;
}

/// (A x) of list entry e: diag x_e - sum over its fluid links of weight x_nb. In double: with stiff
/// paint nu dt reaches 1e9 cells^2, and in float the 1 of the diagonal (the identity of backward
/// Euler) is lost to the rounding of the links' sum; a blob not held by a wall (free slip on all
/// its sides: a Laplacian's null space) then has an indefinite matrix and CG diverges
/// (docs/GRID.md "Viscosity").
WB_HD WB_INLINE double viscous_apply(const float* nu, const int32_t* nb, const double* x, double diag, int64_t e) {
  const float nf = nu[e];
  double off = 0.0;
  for (int q = 0; q < 6; ++q) {
    const int32_t n = nb[6 * e + q];
    if (n < 0) break;
    off += double(link_nu(nf, nu[n])) * x[n];
  }
  return diag * x[e] - off;
}

}  // namespace wb
