// Grid <-> particle liquid transfer (paper §5.2, Eq. 15-16): the per-element physics.
// Cells within D0 of the bristles turn into particles (27 stratified candidates per cell,
// kept where the interpolated density is positive); slow particles beyond D0 go back to the
// cells. Both directions spread a particle's mass over the cells with the kernel W of length
// h, normalised over the cells it touches, so the grid changes by exactly the particle mass.
#pragma once
#include <cstdint>

#include "core/canvas/window.h"
#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// Squared distance standing for "no sample anywhere" in the distance transform.
inline constexpr float kFarDistance2 = 1e20f;

/// Dried paint is solid (dried_solid): it neither becomes particles nor receives them (§4.2 "dryness").
WB_HD WB_INLINE bool cell_is_solid(float density, float dryness, float dry_threshold) {
  return dried_solid(density, dryness, dry_threshold);
}

/// A cell-centred window scalar field (cell (i,j,k) centre at (i+1/2, j+1/2, k+1/2)).
struct CellField {
  const float* f;
  int nx, ny, nz;
  int ox, oy, oz;  ///< canvas cell of the field's (0,0,0)
};

/// Whether canvas point p lies over the columns of g, at any height: over the active window's,
/// where the particles live and the swept contact lays paint.
WB_HD WB_INLINE bool over_columns(const CellField& g, Vec3 p) {
  return p.x >= float(g.ox) && p.x < float(g.ox + g.nx) && p.y >= float(g.oy) && p.y < float(g.oy + g.ny);
}

/// p moved over the columns of g, at least half a cell inside their walls.
WB_HD WB_INLINE Vec3 into_columns(const CellField& g, Vec3 p) {
  p.x = clampf(p.x, float(g.ox) + 0.5f, float(g.ox + g.nx) - 0.5f);
  p.y = clampf(p.y, float(g.oy) + 0.5f, float(g.oy + g.ny) - 0.5f);
  return p;
}

/// Fixed point of order-independent sums (DepositScratch): 2^-40 per unit (9e-13 of a cell,
/// 7e-21 kg), exact for any float of at least 2^-40 and far from overflow (2^23 cells a cell).
WB_HD WB_INLINE int64_t to_fixed(float v) { return llrintf(v * 1099511627776.f); }
WB_HD WB_INLINE double from_fixed_sum(int64_t v) { return double(v) * (1.0 / 1099511627776.0); }
WB_HD WB_INLINE float from_fixed(int64_t v) { return float(from_fixed_sum(v)); }

/// Trilinear sum over the 8 cell centres of g's lattice around canvas position p: the weight of
/// each node in the field times value(index of the cell); nodes outside the field are left out.
template <class Value>
WB_HD WB_INLINE float trilinear_cells(const CellField& g, Vec3 p, Value&& value) {
  const float sx = p.x - float(g.ox) - 0.5f, sy = p.y - float(g.oy) - 0.5f, sz = p.z - float(g.oz) - 0.5f;
  const float fx = floorf(sx), fy = floorf(sy), fz = floorf(sz);
  const int i0 = int(fx), j0 = int(fy), k0 = int(fz);
  const float tx = sx - fx, ty = sy - fy, tz = sz - fz;
  float acc = 0.f;
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const int i = i0 + a, j = j0 + b, k = k0 + c;
        if (i < 0 || j < 0 || k < 0 || i >= g.nx || j >= g.ny || k >= g.nz) continue;
        const float w = (a ? tx : 1.f - tx) * (b ? ty : 1.f - ty) * (c ? tz : 1.f - tz);
        acc += w * value((int64_t(k) * g.ny + j) * g.nx + i);
      }
  return acc;
}

/// Trilinear value of a cell-centred field at canvas position p; nodes outside the field read 0.
WB_HD WB_INLINE float cell_field_at(const CellField& g, Vec3 p) {
  if (g.f == nullptr) return 0.f;
  return trilinear_cells(g, p, [&](int64_t id) { return g.f[id]; });
}

/// Trilinear value of the dried (solid, `cell_is_solid`) part of a cell-centred density field at
/// canvas position p: wet cells count as empty; nodes outside the field read 0. The dryness of
/// each cell decides, not an interpolated dryness (air cells have none, and interpolating it
/// across a dried top put that top half a cell too low).
WB_HD WB_INLINE float dried_density_at(const CellField& density, const CellField& dryness, float dry_threshold, Vec3 p) {
  if (density.f == nullptr) return 0.f;
  return trilinear_cells(density, p, [&](int64_t id) {
    const float rho = density.f[id];
    return cell_is_solid(rho, dryness.f[id], dry_threshold) ? rho : 0.f;
  });
}

/// Trilinear density of the liquid (non-solid) paint at window position q, constant
/// extension at the window's edges; solid cells count as empty. Used to keep candidates.
WB_HD WB_INLINE float liquid_density_at(const PaintWindowView& pw, Vec3 q, float dry_threshold) {
  const float sx = q.x - 0.5f, sy = q.y - 0.5f, sz = q.z - 0.5f;
  const float fx = floorf(sx), fy = floorf(sy), fz = floorf(sz);
  const int i0 = int(fx), j0 = int(fy), k0 = int(fz);
  const float tx = sx - fx, ty = sy - fy, tz = sz - fz;
  float acc = 0.f;
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const int i = clampi(i0 + a, 0, pw.nx - 1), j = clampi(j0 + b, 0, pw.ny - 1), k = clampi(k0 + c, 0, pw.nz - 1);
        const int64_t id = pw.index(i, j, k);
        const float rho = pw.density[id];
        if (cell_is_solid(rho, pw.dryness[id], dry_threshold)) continue;
        acc += (a ? tx : 1.f - tx) * (b ? ty : 1.f - ty) * (c ? tz : 1.f - tz) * rho;
      }
  return acc;
}

/// 32-bit integer hash (Wang / Jenkins mix), for the deterministic candidate jitter.
WB_HD WB_INLINE uint32_t transfer_hash(uint32_t x) {
  x = (x ^ 61u) ^ (x >> 16);
  x *= 9u;
  x ^= x >> 4;
  x *= 0x27d4eb2du;
  x ^= x >> 15;
  return x;
}

/// Candidate s (0..n^3-1) of the canvas cell (cx, cy, cz): the centre of sub-cell (s%n, s/n%n,
/// s/n^2) of the n x n x n split, jittered within the sub-cell by up to +-1/3 of its size,
/// deterministically from the canvas cell and s (§5.2 "stratified sampling ... 27 particle
/// candidates": n = 3). Returns the offset inside the cell, in [0,1)^3.
WB_HD WB_INLINE Vec3 candidate_offset(int cx, int cy, int cz, int s, int n) {
  const uint32_t seed = transfer_hash(uint32_t(cx) * 73856093u ^ uint32_t(cy) * 19349663u ^ uint32_t(cz) * 83492791u ^
                                      uint32_t(s) * 2654435761u);
  const float jx = float(seed & 1023u) / 1023.f - 0.5f;
  const float jy = float((seed >> 10) & 1023u) / 1023.f - 0.5f;
  const float jz = float((seed >> 20) & 1023u) / 1023.f - 0.5f;
  const float part = 1.f / float(n);
  return Vec3((float(s % n) + 0.5f + jx * 0.666f) * part, (float((s / n) % n) + 0.5f + jy * 0.666f) * part,
              (float(s / (n * n)) + 0.5f + jz * 0.666f) * part);
}

/// Candidates per axis for a cell of density rho (docs/TRANSFER.md "Grid → particles"): the n^3 of
/// Eq. 15 (n = candidate_split) where the cell is full, fewer where it holds less, so that each
/// candidate carries at least a 1/n^3 share of a full cell: n' = the largest in [1, n] with
/// n'^3 <= rho n^3. A thin cell is one candidate, not n^3 specks.
WB_HD WB_INLINE int cell_candidate_split(float rho, int n) {
  const float full = rho * float(n * n * n);
  int s = n;
  while (s > 1 && float(s * s * s) > full) --s;
  return s;
}

/// Tent weight of one axis: max(1 - |d| / h, 0).
WB_HD WB_INLINE float tent(float d, float h) { return maxf(1.f - fabsf(d) / h, 0.f); }

/// The kernel W(p - x_c, h) of Eq. 15-16 at window position q over the liquid cells of the
/// window: a separable tent of half-width h around q, normalised so that its weights over the
/// cells it touches (inside the window, not solid) sum to one. Calls f(cell index, weight) for
/// each such cell and returns the number of cells (0: none, q cannot exchange with the grid).
template <typename F>
WB_HD WB_INLINE int for_each_kernel_cell(const PaintWindowView& pw, Vec3 q, float h, float dry_threshold, F f) {
  const int i0 = imax(int(ceilf(q.x - 0.5f - h)), 0), i1 = imin(int(floorf(q.x - 0.5f + h)), pw.nx - 1);
  const int j0 = imax(int(ceilf(q.y - 0.5f - h)), 0), j1 = imin(int(floorf(q.y - 0.5f + h)), pw.ny - 1);
  const int k0 = imax(int(ceilf(q.z - 0.5f - h)), 0), k1 = imin(int(floorf(q.z - 0.5f + h)), pw.nz - 1);
  // Every liquid-capable cell the tent touches, with its raw weight.
  auto visit = [&](auto&& g) {
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const float w = tent(q.x - (float(i) + 0.5f), h) * tent(q.y - (float(j) + 0.5f), h) *
                          tent(q.z - (float(k) + 0.5f), h);
          if (!(w > 0.f)) continue;
          const int64_t id = pw.index(i, j, k);
          if (!cell_is_solid(pw.density[id], pw.dryness[id], dry_threshold)) g(id, w);
        }
  };
  float sum = 0.f;
  int n = 0;
  visit([&](int64_t, float w) {
    sum += w;
    ++n;
  });
  if (!(sum > 0.f)) return 0;
  visit([&](int64_t id, float w) { f(id, w / sum); });  // divided: sum may be subnormal
  return n;
}

/// Eq. 15 with the clamp kept exact: a cell asked for `demand` (density units) by the new
/// particles' kernels gives removed = min(demand, available); every particle then keeps
/// ratio = removed / demand of what it asked from that cell, so the particles' mass equals
/// the removed density and the clamp creates no paint. Returns ratio (1 when demand is 0).
WB_HD WB_INLINE float clamp_ratio(float demand, float available, float& removed) {
  if (!(demand > 0.f)) {
    removed = 0.f;
    return 1.f;
  }
  removed = minf(demand, maxf(available, 0.f));
  return removed >= demand ? 1.f : removed / demand;
}

// --- coarse distance to the bristles (decides "within D0", §5.2) ---------------------

/// One line of the exact squared Euclidean distance transform (Felzenszwalb & Huttenlocher
/// 2012): out[q] = min_p (f[p] + (q - p)^2) over n entries at `stride`; v (n ints) and z
/// (n + 1 floats) are scratch. f entries of kFarDistance2 or more mean "no site".
WB_HD WB_INLINE void edt_line(const float* f, float* out, int n, int64_t stride, int* v, float* z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    const float fq = f[q * stride];
    if (fq >= kFarDistance2) continue;
    float s = 0.f;
    while (k >= 0) {
      const int p = v[k];
      const float fp = f[p * stride];
      s = ((fq + float(q) * float(q)) - (fp + float(p) * float(p))) / (2.f * float(q - p));
      if (s <= z[k]) {
        --k;
      } else {
        break;
      }
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -1e30f : s;
    z[k + 1] = 1e30f;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) out[q * stride] = kFarDistance2;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < float(q)) ++j;
    const float d = float(q - v[j]);
    out[q * stride] = d * d + f[v[j] * stride];
  }
}

/// Coarse block grid of the bristle distance field: blocks of `block` cells over the window,
/// extended by `margin` blocks on every side so that samples outside the window still count.
/// Box of window cells [lo, hi) the particles may live in (TransferEnv::keep); on == 0: all
/// of the window. Particles outside it go to the grid (Eq. 16) and cells outside it are never
/// sampled into particles (Eq. 15): docs/TRANSFER.md, "The window's rim".
struct KeepBox {
  int on = 0;
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  static KeepBox of(Int3 l, Int3 h) { return KeepBox{1, {l.x, l.y, l.z}, {h.x, h.y, h.z}}; }
  WB_HD bool contains(int i, int j, int k) const {
    return !on || (i >= lo[0] && j >= lo[1] && k >= lo[2] && i < hi[0] && j < hi[1] && k < hi[2]);
  }
  /// The same for a position in window cells.
  WB_HD bool contains(Vec3 q) const {
    return !on || (q.x >= float(lo[0]) && q.y >= float(lo[1]) && q.z >= float(lo[2]) && q.x < float(hi[0]) &&
                   q.y < float(hi[1]) && q.z < float(hi[2]));
  }
};

struct DistanceBlocks {
  float* d;  ///< distance to the nearest occupied block, in blocks (kFarDistance2 where none)
  int bx, by, bz;
  int block;
  int margin;
  float D0;  ///< cells
  /// The lattice's offset this step, cells in [0, block) on each axis: its blocks' edges lie at
  /// the brush's anchor plus whole blocks (Transfer::update_distance), so the lattice travels with
  /// the bristles (docs/TRANSFER.md "Ribs on slow strokes").
  Vec3 shift;
  WB_HD int64_t index(int i, int j, int k) const { return (int64_t(k) * by + j) * bx + i; }
  /// Block of window position q (may fall outside: then -1).
  WB_HD int64_t block_of(Vec3 q) const {
    const float inv = 1.f / float(block);
    const int i = int(floorf((q.x + shift.x) * inv)) + margin, j = int(floorf((q.y + shift.y) * inv)) + margin,
              k = int(floorf((q.z + shift.z) * inv)) + margin;
    if (i < 0 || j < 0 || k < 0 || i >= bx || j >= by || k >= bz) return -1;
    return index(i, j, k);
  }
  /// Distance from window position q to the bristles, cells: the block centres' distances
  /// (exact between block centres, so within +-block*sqrt(3) of the true distance) interpolated
  /// trilinearly, so the D0 front has no block's steps in space. A block is marked or not; on a
  /// lattice that travels with the brush the marked blocks change only as the bristles change
  /// shape, not as they cross the lattice's edges, so the front has no steps in time either.
  /// Huge outside the field or with no bristle in it.
  WB_HD float distance(Vec3 q) const {
    if (block_of(q) < 0) return 1e30f;
    const float inv = 1.f / float(block);
    const float fx = (q.x + shift.x) * inv - 0.5f + float(margin), fy = (q.y + shift.y) * inv - 0.5f + float(margin),
                fz = (q.z + shift.z) * inv - 0.5f + float(margin);
    const int i0 = imin(imax(int(floorf(fx)), 0), bx - 2), j0 = imin(imax(int(floorf(fy)), 0), by - 2),
              k0 = imin(imax(int(floorf(fz)), 0), bz - 2);
    // minf / maxf, not fminf / fmaxf: the CPU build calls the library for those (their NaN rule)
    // on every particle.
    const float tx = minf(maxf(fx - float(i0), 0.f), 1.f), ty = minf(maxf(fy - float(j0), 0.f), 1.f),
                tz = minf(maxf(fz - float(k0), 0.f), 1.f);
    float dist = 0.f;
    for (int c = 0; c < 8; ++c) {
      const int di = c & 1, dj = (c >> 1) & 1, dk = c >> 2;
      const float v = d[index(i0 + di, j0 + dj, k0 + dk)];
      if (v >= kFarDistance2) return 1e30f;
      dist += (di ? tx : 1.f - tx) * (dj ? ty : 1.f - ty) * (dk ? tz : 1.f - tz) * v;
    }
    return dist * float(block);
  }
  /// Within D0 of the bristles; nothing is near when D0 is 0 (grid-only paint, Fig. 7).
  WB_HD bool near(Vec3 q) const { return D0 > 0.f && distance(q) <= D0; }
  /// Within D0 + margin (the particles' side of the hysteresis, TransferParams::return_margin).
  WB_HD bool near(Vec3 q, float margin) const { return D0 > 0.f && distance(q) <= D0 + margin; }
};

}  // namespace wb
