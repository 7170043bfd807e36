// Grid stage, advection (paper §4.2). The velocity is advected semi-Lagrangianly (Stam 1999:
// trilinear sampling of the staggered field, RK2 backtrace); the paint is moved in flux form
// with semi-Lagrangian fluxes (finite volumes on the MAC faces, each face's flux the paint
// between it and its departure point), so every cell gives exactly what its neighbours receive
// and a pass costs the same at any speed.
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

/// What crosses a face in one pass: the paint (cell volumes, positive along +axis) and the
/// pigment, oil and dryness it carries (each times the paint).
struct FaceCarry {
  float m = 0.f, r = 0.f, y = 0.f, b = 0.f, oil = 0.f, dry = 0.f;
  /// Adds `part` cell volumes of cell c's paint.
  WB_HD void add(const PaintWindowView& p, int64_t c, float part) {
    m += part;
    r += part * p.pigment_r[c];
    y += part * p.pigment_y[c];
    b += part * p.pigment_b[c];
    oil += part * p.oil[c];
    dry += part * p.dryness[c];
  }
};

/// (e^x - 1) / x, and log(1 + x) / x: the exact motion through a cell whose velocity is linear
/// between its faces (below), with their limits at x -> 0 written out where the quotient loses
/// its digits.
WB_HD WB_INLINE float expm1_over(float x) {
  return fabsf(x) < 1e-3f ? 1.f + x * (0.5f + x * (1.f / 6.f)) : expm1f(x) / x;
}
WB_HD WB_INLINE float log1p_over(float x) {
  return fabsf(x) < 1e-3f ? 1.f - x * (0.5f - x * (1.f / 3.f)) : log1pf(x) / x;
}

/// The paint that crosses face (c; i,j,k) in one pass of time dt along axis c: the paint lying,
/// at the pass's start, between the face and the point whose path along the axis ends on the
/// face (its departure point). The path is followed exactly through the velocity the faces of
/// the axis carry (the mixture velocity, linear across each cell), so its length is not bounded
/// by one cell: a pass costs the same at any speed, and the walk visits as many cells as the
/// paint really comes from (flux-form semi-Lagrangian; Lin & Rood 1996, Leonard et al. 1996).
/// The whole cells on the way count whole; the last one its swept part of the donor's density
/// plus its van Leer-limited slope (van Leer 1977; LeVeque 2002, §6.12).
///
/// Paths along one axis never cross, so the departure points of a cell's two faces bound an
/// interval and the cell's new paint is what lay in it: never negative, with no donor limit.
/// Both cells a face joins compute its flux from the same values, bit for bit, so mass is kept
/// exactly. A closed face (a wall, a solid cell's) carries no flow and stops every path. The
/// walk stops after `reach` cells and at the bounds [lo, hi) of the cells whose faces were
/// classified this step: the paint's reach and the box around it (Grid::advect); a path cut
/// there still bounds an interval, so both properties hold.
WB_HD WB_INLINE FaceCarry face_paint_carry(const GridView& g, const PaintWindowView& p, int c, int i, int j, int k,
                                           float dt, int reach, int lo, int hi) {
  FaceCarry out;
  const float U = face_volume_flux(g, c, i, j, k);
  if (U == 0.f) return out;
  const GridDims& d = g.d;
  const int sgn = U > 0.f ? 1 : -1;
  const int at = c == 0 ? i : (c == 1 ? j : k);
  const int64_t stride = c == 0 ? 1 : (c == 1 ? int64_t(d.nx) : int64_t(d.nx) * d.ny);
  const int64_t row = d.cell(c == 0 ? 0 : i, c == 1 ? 0 : j, c == 2 ? 0 : k);
  auto face_speed = [&](int f) {  // along the walk (upwind), cells/s
    return float(sgn) * face_volume_flux(g, c, c == 0 ? f : i, c == 1 ? f : j, c == 2 ? f : k);
  };
  int s = sgn > 0 ? at - 1 : at;  // the cell the path comes through, from the face upwind
  float w_in = fabsf(U), tau = dt;
  for (int n = 0; n < reach && s >= lo && s < hi; ++n, s -= sgn) {
    const int64_t cs = row + int64_t(s) * stride;
    // The velocity along the walk is w_in at the face the path leaves s by, w_out at the face it
    // entered s through, linear between: back in time the path moves by dx/dt' = w, so w grows
    // (or decays) as e^{(w_out - w_in) t'}, and it crosses s in log(w_out / w_in) / (w_out - w_in)
    // when w_out > 0; it never reaches a face where the flow stops or turns.
    const float w_out = face_speed(sgn > 0 ? s : s + 1), h = w_out - w_in;
    const float cross = w_out > 0.f ? log1p_over(h / w_in) / w_in : INFINITY;
    const float rho = p.density[cs];
    if (cross < tau && n + 1 < reach) {
      out.add(p, cs, sgn * rho);
      tau -= cross;
      w_in = w_out;
      continue;
    }
    // The path starts in s: the swept part eta of it, from the face it leaves s by.
    if (rho > 0.f) {
      const float eta = minf(w_in * tau * expm1_over(h * tau), 1.f);
      // Slope along the flow from s's upwind neighbour and the cell it flows into.
      const int su = s - sgn, sr = s + sgn;
      const float rr = sr >= 0 && sr < (c == 0 ? d.nx : (c == 1 ? d.ny : d.nz)) ? p.density[cs + sgn * stride] : rho;
      float slope = 0.f;
      if (su >= lo && su < hi) {
        const int64_t up = cs - sgn * stride;
        if (g.cls[up] != kCellSolid) {
          const float d1 = rho - p.density[up], d2 = rr - rho;
          slope = d1 * d2 > 0.f ? 2.f * d1 * d2 / (d1 + d2) : 0.f;  // van Leer's harmonic limiter
        }
      }
      // The limited value lies between the donor's and the next cell's; clamping to that
      // interval removes round-off only.
      const float face = clampf(rho + 0.5f * (1.f - eta) * slope, minf(rho, rr), maxf(rho, rr));
      out.add(p, cs, sgn * (eta * face));
    }
    break;
  }
  return out;
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
