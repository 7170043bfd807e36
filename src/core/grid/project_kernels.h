// Grid stage, pressure projection (paper §4.2, Algorithm 1, Eq. 3-7): cell classes,
// open face fractions from the bristle density psi (Batty et al. 2007), the divergence
// right-hand side, the Jacobi-type sweeps of every solver behind Grid::project(), the
// pressure gradient update, velocity extrapolation into air, and gravity with its
// hydrostatic part split off. Pressure p is scaled so that the update is u -= grad p.
#pragma once
#include <math.h>

#include <cstdint>

#include "core/canvas/paint_fields.h"
#include "core/grid/grid_fields.h"
#include "core/math/vec.h"

namespace wb {

/// Cell class from paint and canvas: solid when off the canvas or dried (dried_solid, §4.2 "we
/// treat it as a solid cell"), liquid when density >= the liquid threshold, else air.
WB_HD WB_INLINE uint8_t classify_cell(float density, float dryness, bool on_canvas, float liquid_threshold,
                                      float dry_threshold) {
  if (!on_canvas) return kCellSolid;
  if (dried_solid(density, dryness, dry_threshold)) return kCellSolid;
  return density >= liquid_threshold ? kCellLiquid : kCellAir;
}

/// The two cells a face of component c separates: a = (i,j,k) - e_c, b = (i,j,k).
/// Sets has_a / has_b to whether they lie in the window.
WB_HD WB_INLINE void face_cells(const GridDims& d, int c, int i, int j, int k, int64_t& a, int64_t& b, bool& has_a,
                                bool& has_b) {
  const int ia = i - (c == 0), ja = j - (c == 1), ka = k - (c == 2);
  has_a = ia >= 0 && ja >= 0 && ka >= 0;
  has_b = i < d.nx && j < d.ny && k < d.nz;
  a = has_a ? d.cell(ia, ja, ka) : -1;
  b = has_b ? d.cell(i, j, k) : -1;
}

/// Open fraction and solid velocity of one face. Closed (0) at the canvas floor, the window's
/// side walls and against solid cells; open to air at the window top. In between,
/// theta = 1 - (min(psi_a,1) + min(psi_b,1)) / 2 and the solid velocity is the psi-weighted
/// mean bristle velocity of the two cells (moving-solid boundary, §4.1 last paragraph).
WB_HD WB_INLINE void face_fraction(const GridDims& d, const uint8_t* cls, BristleField br, int c, int i, int j, int k,
                                   float& theta, float& us) {
  int64_t a, b;
  bool ha, hb;
  face_cells(d, c, i, j, k, a, b, ha, hb);
  theta = 0.f;
  us = 0.f;
  const bool top = (c == 2 && k == d.nz);
  if (!(ha && hb) && !top) return;  // floor and side walls
  if ((ha && cls[a] == kCellSolid) || (hb && cls[b] == kCellSolid)) return;
  float pa = 0.f, pb = 0.f, va = 0.f, vb = 0.f;
  if (br.psi) {
    const float* comp = c == 0 ? br.vx : (c == 1 ? br.vy : br.vz);
    if (ha) {
      pa = minf(maxf(br.psi[a], 0.f), 1.f);
      va = comp ? comp[a] : 0.f;
    }
    if (hb) {
      pb = minf(maxf(br.psi[b], 0.f), 1.f);
      vb = comp ? comp[b] : 0.f;
    }
  }
  theta = top ? 1.f - pa : 1.f - 0.5f * (pa + pb);
  us = (pa + pb) > 1e-6f ? (pa * va + pb * vb) / (pa + pb) : 0.f;
}

/// True when the face touches a liquid cell and is at least partly open.
WB_HD WB_INLINE bool face_is_fluid(const GridDims& d, const uint8_t* cls, const float* theta_c, int c, int i, int j,
                                   int k) {
  if (theta_c[d.fidx(c, i, j, k)] <= 0.f) return false;
  int64_t a, b;
  bool ha, hb;
  face_cells(d, c, i, j, k, a, b, ha, hb);
  return (ha && cls[a] == kCellLiquid) || (hb && cls[b] == kCellLiquid);
}

/// Net flux out of cell (i,j,k): sum over its faces of +-(theta u + (1 - theta) u_solid).
/// This is the discrete divergence of the mixture velocity that the projection zeroes.
WB_HD WB_INLINE float cell_divergence(const GridView& g, int i, int j, int k) {
  const GridDims& d = g.d;
  auto flux = [&](int c, int64_t f) { return face_mixture_velocity(g, c, f); };
  return flux(0, d.uidx(i + 1, j, k)) - flux(0, d.uidx(i, j, k)) + flux(1, d.vidx(i, j + 1, k)) -
         flux(1, d.vidx(i, j, k)) + flux(2, d.widx(i, j, k + 1)) - flux(2, d.widx(i, j, k));
}

/// Divergence a liquid cell holding density rho > 1 must have to return to 1 in one step,
/// ln(rho) / dt (rho(t + dt) = rho e^{-div dt}); 0 at or below 1. Paint is incompressible: where
/// an unconverged projection let the flow pack it, the next projection pushes it out again
/// (volume correction, Kim et al. 2007 "Simulation of bubbles" §4; Losasso et al. 2008 §6).
/// Cells below 1 are not pulled in: partly filled cells are the free surface.
WB_HD WB_INLINE float compression_source(float rho, float inv_dt) {
  return rho > 1.f ? logf(rho) * inv_dt : 0.f;
}

/// Diagonal and off-diagonal sum of row i of A: diag = sum theta_f, off = sum theta_f x_nb
/// (x = 0 outside liquid and outside the window). Works for float and double x.
template <typename T>
WB_HD WB_INLINE void poisson_row(const PoissonView& s, const T* x, int i, int j, int k, T& diag, T& off) {
  const GridDims& d = s.d;
  const float tw = s.theta[0][d.uidx(i, j, k)], te = s.theta[0][d.uidx(i + 1, j, k)];
  const float ts = s.theta[1][d.vidx(i, j, k)], tn = s.theta[1][d.vidx(i, j + 1, k)];
  const float tb = s.theta[2][d.widx(i, j, k)], tt = s.theta[2][d.widx(i, j, k + 1)];
  diag = T(tw) + T(te) + T(ts) + T(tn) + T(tb) + T(tt);
  off = T(0);
  if (tw > 0.f && i > 0) off += T(tw) * x[d.cell(i - 1, j, k)];
  if (te > 0.f && i + 1 < d.nx) off += T(te) * x[d.cell(i + 1, j, k)];
  if (ts > 0.f && j > 0) off += T(ts) * x[d.cell(i, j - 1, k)];
  if (tn > 0.f && j + 1 < d.ny) off += T(tn) * x[d.cell(i, j + 1, k)];
  if (tb > 0.f && k > 0) off += T(tb) * x[d.cell(i, j, k - 1)];
  if (tt > 0.f && k + 1 < d.nz) off += T(tt) * x[d.cell(i, j, k + 1)];
}

/// (A x)_i = diag_i x_i - sum theta_f x_nb on liquid cells, 0 elsewhere; cell c is (i, j, k).
template <typename T>
WB_HD WB_INLINE T poisson_apply(const PoissonView& s, const T* x, int64_t c, int i, int j, int k) {
  if (s.cls[c] != kCellLiquid) return T(0);
  T diag, off;
  poisson_row(s, x, i, j, k, diag, off);
  return diag * x[c] - off;
}

/// One weighted Jacobi update of cell c = (i, j, k): (1-omega) x_c + omega D^-1 (b_c + R x)_c,
/// Eq. 7 (omega = 1: plain Jacobi). Cells outside liquid, or closed on every face, stay 0.
WB_HD WB_INLINE float jacobi_update(const PoissonView& s, const float* b, const float* x, int64_t c, int i, int j,
                                    int k, float omega) {
  if (s.cls[c] != kCellLiquid) return 0.f;
  float diag, off;
  poisson_row(s, x, i, j, k, diag, off);
  if (diag <= 1e-6f) return 0.f;
  const float xj = (b[c] + off) / diag;
  return omega == 1.f ? xj : (1.f - omega) * x[c] + omega * xj;
}

/// Chebyshev weight omega_{k+1} of Eq. 6 from omega_k and the spectral-radius estimate rho
/// (Golub & Van Loan 1996, §10.1.5): omega_1 = 1, omega_2 = 2/(2 - rho^2), then 4/(4 - rho^2 omega_k).
WB_HD WB_INLINE float chebyshev_omega(int k, float rho, float omega_prev) {
  if (k <= 0) return 1.f;
  if (k == 1) return 2.f / (2.f - rho * rho);
  return 4.f / (4.f - rho * rho * omega_prev);
}

/// Pressure-gradient update of one face (u -= grad p on the fluid part), after which the
/// face's mixture flux theta u + (1-theta) u_s satisfies the projected divergence. Closed faces
/// take the solid velocity.
WB_HD WB_INLINE float projected_face_velocity(const GridView& g, const float* p, int c, int i, int j, int k) {
  const GridDims& d = g.d;
  const int64_t f = d.fidx(c, i, j, k);
  const float t = g.theta[c][f];
  if (t <= 0.f) return g.solid_vel[c][f];
  int64_t a, b;
  bool ha, hb;
  face_cells(d, c, i, j, k, a, b, ha, hb);
  const bool la = ha && g.cls[a] == kCellLiquid, lb = hb && g.cls[b] == kCellLiquid;
  if (!la && !lb) return g.vel[c][f];
  const float pa = la ? p[a] : 0.f, pb = lb ? p[b] : 0.f;
  return g.vel[c][f] - (pb - pa);
}

/// Velocity of an open face that touches no liquid: mean of the fluid faces of the same
/// component among its 6 neighbours (one layer of extrapolation, so that paint below the
/// liquid threshold moves with its neighbours), 0 when there are none.
WB_HD WB_INLINE float extrapolated_face_velocity(const GridView& g, int c, int i, int j, int k) {
  const GridDims& d = g.d;
  int ex, ey, ez;
  d.face_extent(c, ex, ey, ez);
  float acc = 0.f;
  int n = 0;
  const int di[6] = {-1, 1, 0, 0, 0, 0}, dj[6] = {0, 0, -1, 1, 0, 0}, dk[6] = {0, 0, 0, 0, -1, 1};
  for (int q = 0; q < 6; ++q) {
    const int ii = i + di[q], jj = j + dj[q], kk = k + dk[q];
    if (ii < 0 || jj < 0 || kk < 0 || ii >= ex || jj >= ey || kk >= ez) continue;
    const int64_t nf = d.fidx(c, ii, jj, kk);
    if (!g.fluid[c][nf]) continue;
    acc += g.vel[c][nf];
    ++n;
  }
  return n ? acc / float(n) : 0.f;
}

/// Gravity impulse on one open face adjacent to liquid, with the hydrostatic gradient
/// (p_h of a cell = g dt times the number of contiguous liquid cells from it up to the free
/// surface, so its gradient cancels gravity exactly inside every resting liquid column)
/// subtracted: -g dt e_z + (p_h(a) - p_h(b)) e_c. What is left (unsupported paint, columns of
/// different heights) is resisted by the paint's viscosity, which holds it below the yield
/// stress (rheology.h). On a tilted canvas g_dt is the part across it (g cos(tilt) dt) and
/// g_dt_y the part down its plane (g sin(tilt) dt, +y): nothing balances that one at rest but
/// the yield stress and the canvas's grip through the viscosity.
WB_HD WB_INLINE float gravity_face_impulse(int c, bool la, bool lb, float ph_a, float ph_b, float g_dt, float g_dt_y) {
  float f = (la ? ph_a : 0.f) - (lb ? ph_b : 0.f);
  if (c == 2) f -= g_dt;
  if (c == 1) f += g_dt_y;
  return f;
}

}  // namespace wb
