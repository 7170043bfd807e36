// Grid stage, advection (paper §4.2). The velocity is advected semi-Lagrangianly (Stam 1999:
// trilinear sampling of the staggered field, RK2 backtrace); the paint is moved in flux form
// (finite volumes on the MAC faces), so every cell gives exactly what its neighbours receive.
// Positions are in window cells; velocities in cells/s; dt in s.
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
  // At rest at x the midpoint is x itself and its sample v0 again: the departure point is x,
  // exactly as the full rule gives it. Most faces of the air above the paint are at rest.
  const bool rest = v0.x == 0.f && v0.y == 0.f && v0.z == 0.f;
  const Vec3 mid = x - v0 * (0.5f * dt);
  const Vec3 v1 = rest ? v0 : sample_velocity3(u, v, w, d, mid);
  Vec3 p = x - v1 * dt;
  p.x = clampf(p.x, 0.5f, float(d.nx) - 0.5f);
  p.y = clampf(p.y, 0.5f, float(d.ny) - 0.5f);
  p.z = clampf(p.z, 0.5f, float(d.nz) - 0.5f);
  return p;
}

/// Volume flux through face (c; i,j,k) per unit face area, cells/s: the mixture velocity
/// theta u + (1 - theta) u_solid, whose divergence the projection zeroes (cell_divergence).
/// Zero through closed faces and through every wall of the window (the top included), so
/// paint never leaves the window by advection.
WB_HD WB_INLINE float face_volume_flux(const GridView& g, int c, int i, int j, int k) {
  const GridDims& d = g.d;
  if ((c == 0 && (i == 0 || i == d.nx)) || (c == 1 && (j == 0 || j == d.ny)) || (c == 2 && (k == 0 || k == d.nz)))
    return 0.f;
  return face_mixture_velocity(g, c, d.fidx(c, i, j, k));
}

/// Paint crossing face (c; i,j,k) in time dt as the scheme reconstructs it, density units (cell
/// volumes), positive along +c, and the donor (upwind) cell it leaves. Second-order upwind: the
/// donor's density plus its van Leer-limited slope, evaluated at the centre of the swept region
/// (van Leer 1977; LeVeque 2002, §6.12), so a ridge keeps its edges and no new extremum is made.
/// The slope is 0 where the upwind neighbour is outside the window or solid.
WB_HD WB_INLINE float face_paint_flux_unlimited(const GridView& g, const float* rho, int c, int i, int j, int k,
                                                float dt, int64_t& donor) {
  const GridDims& d = g.d;
  const float U = face_volume_flux(g, c, i, j, k);
  donor = -1;
  if (U == 0.f) return 0.f;
  const int ei = c == 0, ej = c == 1, ek = c == 2;
  // Donor cell s (upwind), receiver r, and the donor's own upwind neighbour u.
  const int sgn = U > 0.f ? 1 : -1;
  const int si = U > 0.f ? i - ei : i, sj = U > 0.f ? j - ej : j, sk = U > 0.f ? k - ek : k;
  const int ri = U > 0.f ? i : i - ei, rj = U > 0.f ? j : j - ej, rk = U > 0.f ? k : k - ek;
  const int ui = si - sgn * ei, uj = sj - sgn * ej, uk = sk - sgn * ek;
  donor = d.cell(si, sj, sk);
  const float rs = rho[donor], rr = rho[d.cell(ri, rj, rk)];
  float slope = 0.f;
  if (ui >= 0 && uj >= 0 && uk >= 0 && ui < d.nx && uj < d.ny && uk < d.nz) {
    const int64_t up = d.cell(ui, uj, uk);
    if (g.cls[up] != kCellSolid) {
      const float d1 = rs - rho[up], d2 = rr - rs;
      slope = d1 * d2 > 0.f ? 2.f * d1 * d2 / (d1 + d2) : 0.f;  // van Leer's harmonic limiter
    }
  }
  const float courant = fabsf(U) * dt;
  // The limited value lies between the donor's and the receiver's; clamping to that interval
  // only removes round-off (rs^2 / r_up - rs(1 - C) ... can come out a few ulps below 0).
  const float face = rs + 0.5f * (1.f - minf(courant, 1.f)) * slope;
  return U * dt * clampf(face, minf(rs, rr), maxf(rs, rr));
}

/// Density below which a cell gives nothing: 1e-30 of a cell is no paint, and the limiter's
/// margin below needs normal (not subnormal) floats.
inline constexpr float kNoPaint = 1e-30f;

/// The paint that crosses face (c; i,j,k) in time dt, with its donor: the reconstructed flux,
/// scaled down where the donor's outflow through its two faces of this axis would exceed what
/// it holds. Below the sub-step Courant bound the scale is 1; it acts only where paint enters a
/// fast cell during the step, or at the work bound, and keeps every density non-negative.
/// Each of the two cells a face joins computes it from the same values, so both get the same
/// number and the exchange is exact.
WB_HD WB_INLINE float face_paint_flux(const GridView& g, const float* rho, int c, int i, int j, int k, float dt,
                                      int64_t& donor) {
  const float F = face_paint_flux_unlimited(g, rho, c, i, j, k, dt, donor);
  if (donor < 0) return 0.f;
  const float held = rho[donor];
  if (!(held > kNoPaint)) return 0.f;
  // The donor's other face along c: its low face when paint leaves it upwards, else its high face.
  const int e = F > 0.f ? -1 : 1;
  const int oi = i + e * (c == 0), oj = j + e * (c == 1), ok = k + e * (c == 2);
  int64_t other_donor;
  const float Fo = face_paint_flux_unlimited(g, rho, c, oi, oj, ok, dt, other_donor);
  const float out = fabsf(F) + (other_donor == donor ? fabsf(Fo) : 0.f);
  // The scale keeps a part in 10^6 back, more than the round-off of the two products, so the
  // donor never goes below 0.
  return out > held ? F * ((held / out) * (1.f - 1e-6f)) : F;
}

/// Outflow of a cell holding paint along axis c, cells/s: the flux out through its two faces of
/// that axis; 0 for empty cells. The axis's passes of the paint's advection are sized by it.
WB_HD WB_INLINE float cell_axis_outflow(const GridView& g, const float* rho, int c, int i, int j, int k) {
  if (!(rho[g.d.cell(i, j, k)] > 0.f)) return 0.f;
  const float lo = face_volume_flux(g, c, i, j, k);
  const float hi = face_volume_flux(g, c, i + (c == 0), j + (c == 1), k + (c == 2));
  return maxf(hi, 0.f) + maxf(-lo, 0.f);
}

/// Position of face (i,j,k) of component c, window cells.
WB_HD WB_INLINE Vec3 face_position(int c, int i, int j, int k) {
  return Vec3(c == 0 ? float(i) : float(i) + 0.5f, c == 1 ? float(j) : float(j) + 0.5f,
              c == 2 ? float(k) : float(k) + 0.5f);
}

}  // namespace wb
