// Brush stage physics (paper §4.1): Eq. 2 in the non-inertial brush frame, the
// position-based inextensibility and bending constraints (Müller et al. 2007),
// collision with the canvas and dried paint, and the minimum-density constraint
// between bristles (Macklin & Müller 2013). Plain WB_HD functions: values in,
// corrections out; no allocation, no backend knowledge.
#pragma once
#include <cstdint>

#include "core/brush/brush_views.h"
#include "core/exec/hd.h"
#include "core/math/trilinear.h"
#include "core/math/vec.h"

namespace wb::brush {

// ---------------------------------------------------------------------------------
// Eq. 2: acceleration in the brush frame
// ---------------------------------------------------------------------------------

/// Eq. 2: dv^B/dt = R_B a - beta_B (vdot^B + w x (w x x^B) + wdot x x^B + 2 w x v^B);
/// a_B is R_B a (already rotated), the four inertial terms are rectilinear, centrifugal,
/// Euler and Coriolis.
WB_HD WB_INLINE Vec3 eq2_acceleration(Vec3 a_B, const BrushFrame& f, Vec3 xb, Vec3 vb, float beta_B) {
  const Vec3 w = f.omega_B;
  const Vec3 inertial = f.vdot_B + cross(w, cross(w, xb)) + cross(f.omegadot_B, xb) + cross(w, vb) * 2.f;
  return a_B - inertial * beta_B;
}

WB_HD WB_INLINE void lerp_index(float g, int n, int& i0, int& i1, float& f) {
  const float c = clampf(g, 0.f, float(n - 1));
  i0 = int(c);
  if (i0 > n - 2) i0 = n - 2 < 0 ? 0 : n - 2;
  i1 = i0 + 1 < n ? i0 + 1 : i0;
  f = c - float(i0);
}

/// Trilinear sample of a cell-centred window field at window-local position `local`
/// (value (x, y, z) sits at (x + 0.5, y + 0.5, z + 0.5)); 0 beyond half a cell outside.
WB_HD WB_INLINE float sample_cell_centred(const float* f, int nx, int ny, int nz, Vec3 local) {
  const float gx = local.x - 0.5f, gy = local.y - 0.5f, gz = local.z - 0.5f;
  if (!(gx >= -0.5f && gy >= -0.5f && gz >= -0.5f && gx <= nx - 0.5f && gy <= ny - 0.5f && gz <= nz - 0.5f)) return 0.f;
  int x0, x1, y0, y1, z0, z1;
  float fx, fy, fz;
  lerp_index(gx, nx, x0, x1, fx);
  lerp_index(gy, ny, y0, y1, fy);
  lerp_index(gz, nz, z0, z1, fz);
  const int64_t sy = nx, sz = int64_t(nx) * ny;
  const float c00 = f[z0 * sz + y0 * sy + x0] * (1 - fx) + f[z0 * sz + y0 * sy + x1] * fx;
  const float c10 = f[z0 * sz + y1 * sy + x0] * (1 - fx) + f[z0 * sz + y1 * sy + x1] * fx;
  const float c01 = f[z1 * sz + y0 * sy + x0] * (1 - fx) + f[z1 * sz + y0 * sy + x1] * fx;
  const float c11 = f[z1 * sz + y1 * sy + x0] * (1 - fx) + f[z1 * sz + y1 * sy + x1] * fx;
  return (c00 * (1 - fy) + c10 * fy) * (1 - fz) + (c01 * (1 - fy) + c11 * fy) * fz;
}

/// Drag term of a_i (Eq. 2, §4.3): the velocity change k rho (u - v) dt over one step,
/// limited to (u - v) so that a stiff drag relaxes to the flow instead of overshooting.
WB_HD WB_INLINE Vec3 drag_velocity_change(const DragField& d, Vec3 x, Vec3 v, float dt) {
  const Vec3 local(x.x - d.ox, x.y - d.oy, x.z - d.oz);
  const float rho = sample_cell_centred(d.density, d.nx, d.ny, d.nz, local);
  if (!(rho > 0.f)) return Vec3();
  const Vec3 u = sample_mac(d.u, d.v, d.w, d.nx, d.ny, d.nz, local);
  const float s = minf(d.k * rho * dt, 1.f);
  return (u - v) * s;
}

/// Limits |v| to vmax (a bristle cannot leave its ferrule by more than its length a step).
/// A non-finite v passes through unchanged: the step's finiteness check must see it.
WB_HD WB_INLINE Vec3 clamp_length(Vec3 v, float vmax) {
  const float l2 = length2(v);
  if (l2 > vmax * vmax && isfinite(l2)) return v * (vmax / sqrtf(l2));
  return v;
}

// ---------------------------------------------------------------------------------
// Position-based constraints (Müller et al. 2007), one-sided along the bristle: the
// parent (closer to the pinned root) is already projected in the Gauss-Seidel sweep.
// ---------------------------------------------------------------------------------

/// Inextensibility C = |x - x_p| - l0 = 0, projected onto x only:
/// x <- x_p + l0 (x - x_p)/|x - x_p|. Left alone within tol (keeps a rest shape bit-exact).
WB_HD WB_INLINE Vec3 project_distance(Vec3 xp, Vec3 x, float l0, float tol, Vec3 fallback_dir) {
  const Vec3 d = x - xp;
  const float l = length(d);
  if (fabsf(l - l0) <= tol) return x;
  return xp + normalize_or(d, fallback_dir) * l0;
}

/// Bending: C = x - (x_p + l0 t) = 0 with t the direction the segment would have in its
/// rest shape (the parent segment's direction for a straight bristle; the ferrule's
/// rest direction for the first segment). Correction scaled by the per-iteration stiffness k.
WB_HD WB_INLINE Vec3 project_bending(Vec3 x, Vec3 target, float k, float tol) {
  const Vec3 d = target - x;
  if (length2(d) <= tol * tol) return x;
  return x + d * k;
}

/// Per-iteration stiffness that gives stiffness s per step at the reference iteration count
/// (Müller et al. 2007 §3.3: k' = 1 - (1 - k)^(1/n)); `s` is defined at kReferenceIterations.
inline constexpr int kReferenceIterations = 8;

// ---------------------------------------------------------------------------------
// Collision with the canvas plane z = 0 and dried paint (cell (i,j,k) spans
// [i,i+1) x [j,j+1) x [k,k+1) in canvas cells).
// ---------------------------------------------------------------------------------

WB_HD WB_INLINE int floor_to_int(float v) {
  const float f = floorf(v);
  return f < -1e9f ? -1000000000 : (f > 1e9f ? 1000000000 : int(f));
}

/// True when canvas cell (cx, cy, cz) is dried paint the brush rests on (dried_solid).
WB_HD WB_INLINE bool solid_cell(const SolidField& s, int cx, int cy, int cz) {
  if (!s.valid) return false;
  const TileStoreView& t = s.tiles;
  if (!t.inside(cx, cy, cz)) return false;
  const int32_t slot = t.slot_of_tile[(cy / kTileSize) * t.tiles_x + cx / kTileSize];
  if (slot < 0) return false;
  const int64_t at = int64_t(slot) * t.tile_cells() + t.cell_offset(cx % kTileSize, cy % kTileSize, cz);
  // With the drying the tile has not stored yet (TileStoreView::dryness_at), on the 16-bit lattice.
  return t.density[at] >= kSolidDensity && t.dryness_at(slot, at) * 65535.f >= s.dryness_threshold * 65535.f - 0.5f;
}

/// Top of the dried paint in cell (cx, cy, cz), the top of a run of dried cells: the paint fills
/// the cell from below to its density (as the particles' and the transfer's dried surface reads
/// it, column_solid_tops and dried_density_at), so a half-filled top cell is a half-cell step, not
/// a whole one. A whole-cell top held the bristles up to half a cell above the surface that the
/// transfer measured their gap from, and a light brush laid nothing on such a stroke.
WB_HD WB_INLINE float dried_top_of(const SolidField& s, int cx, int cy, int cz) {
  const TileStoreView& t = s.tiles;
  const int32_t slot = t.slot_of_tile[(cy / kTileSize) * t.tiles_x + cx / kTileSize];
  const int64_t at = int64_t(slot) * t.tile_cells() + t.cell_offset(cx % kTileSize, cy % kTileSize, cz);
  const float fill = t.density[at];
  return float(cz) + (fill < 1.f ? fill : 1.f);
}

/// Height a point at x must be lifted to: 0 below the canvas plane, the top of the run of
/// dried cells containing it when it is inside dried paint, else 0 (no contact above z = 0).
WB_HD WB_INLINE float support_height(const SolidField& s, Vec3 x) {
  float h = 0.f;
  if (s.valid) {
    const int cx = floor_to_int(x.x), cy = floor_to_int(x.y);
    int cz = x.z < 0.f ? 0 : floor_to_int(x.z);
    if (solid_cell(s, cx, cy, cz)) {
      while (cz + 1 < s.tiles.depth && solid_cell(s, cx, cy, cz + 1)) ++cz;
      const float top = dried_top_of(s, cx, cy, cz);
      if (x.z < top) h = top;
    }
  }
  return h;
}

/// Lifted height of the dried paint (or the canvas) directly under x within `reach` cells
/// below it: the ground a sample rests on, for contact tests. Returns -1e30 when none.
WB_HD WB_INLINE float ground_below(const SolidField& s, Vec3 x, float reach) {
  if (x.z - reach < 0.f) return 0.f;
  if (s.valid) {
    const int cx = floor_to_int(x.x), cy = floor_to_int(x.y);
    const int top = floor_to_int(x.z) < s.tiles.depth - 1 ? floor_to_int(x.z) : s.tiles.depth - 1;
    const int bottom = floor_to_int(x.z - reach);
    for (int cz = top; cz >= bottom && cz >= 0; --cz)
      if (solid_cell(s, cx, cy, cz)) return dried_top_of(s, cx, cy, cz);
  }
  return -1e30f;
}

/// Pushes vertex x (canvas frame) out of the canvas and dried paint. Where the parent is
/// above the support, x swings about the parent onto the support height so that the
/// segment keeps its length (a pressed bristle splays rather than stretches); the
/// horizontal direction is the segment's own, else `fallback_h`. Returns true on contact.
WB_HD WB_INLINE bool collide_vertex(Vec3& x, Vec3 xp, float l0, const SolidField& s, Vec3 fallback_h) {
  const float h = support_height(s, x);
  if (x.z >= h) return false;
  const float dz = h - xp.z;  // <= 0 when the parent is above the support
  if (dz <= 0.f && -dz < l0) {
    const Vec3 hd = normalize_or(Vec3(x.x - xp.x, x.y - xp.y, 0.f), fallback_h);
    const float r = sqrtf(maxf(l0 * l0 - dz * dz, 0.f));
    x = Vec3(xp.x + hd.x * r, xp.y + hd.y * r, h);
    const float h2 = support_height(s, x);  // the swing may end inside a neighbouring column
    if (x.z < h2) x.z = h2;
  } else {
    x.z = h;
  }
  return true;
}

/// Coulomb-like friction as a position correction: removes the fraction mu of the
/// tangential (x, y) displacement of a contact vertex since the start of the step.
WB_HD WB_INLINE Vec3 apply_friction(Vec3 x, Vec3 x_start, float mu) {
  return Vec3(x.x - (x.x - x_start.x) * mu, x.y - (x.y - x_start.y) * mu, x.z);
}

// ---------------------------------------------------------------------------------
// Minimum-density constraint (Macklin & Müller 2013): vertex density from vertices of
// other bristles with W(r) = (1 - r/h)^2, h = 2 s_min; rho0 = W(s_min) = 1/4, so that a
// lone pair is held exactly at s_min and a crowd at the equivalent density. Unilateral:
// only rho > rho0 is corrected.
// ---------------------------------------------------------------------------------

WB_HD WB_INLINE float density_kernel(float r, float h) {
  if (r >= h) return 0.f;
  const float q = 1.f - r / h;
  return q * q;
}
/// dW/dr of density_kernel (<= 0).
WB_HD WB_INLINE float density_kernel_dr(float r, float h) {
  if (r >= h) return 0.f;
  return -2.f * (1.f - r / h) / h;
}

/// Hash of an integer grid cell into a power-of-two table (Teschner et al. 2003 primes, then mixed).
WB_HD WB_INLINE uint32_t hash_cell(int cx, int cy, int cz, uint32_t mask) {
  uint32_t h = (uint32_t(cx) * 73856093u) ^ (uint32_t(cy) * 19349663u) ^ (uint32_t(cz) * 83492791u);
  h ^= h >> 16;  // avalanche (murmur3 finaliser): the low bits alone would alias neighbouring cells
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  return h & mask;
}

/// Deterministic unit direction separating two coincident vertices (the gradient of the
/// kernel is undefined at r = 0).
WB_HD WB_INLINE Vec3 separation_dir(int64_t a, int64_t b) {
  const uint32_t h = uint32_t(a * 2654435761u) ^ uint32_t(b * 40503u);
  const float ang = float(h & 0xFFFFu) * (6.2831853f / 65536.f);
  const Vec3 d(cosf(ang), sinf(ang), 0.f);
  return a < b ? d : -d;
}

}  // namespace wb::brush
