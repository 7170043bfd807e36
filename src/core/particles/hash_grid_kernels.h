// Neighbour search between liquid particles and bristle samples (paper §4.3, §6: the
// sorted hash list of Green 2010). Samples are hashed into a uniform grid of cells;
// after a radix sort by bucket each bucket is a contiguous range [start, end). A
// particle finds its nearest sample by visiting shells of cells outwards.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// Coarse cells of the occupancy table are kCoarseCells x kCoarseCells x kCoarseCells hash cells.
constexpr int kCoarseShift = 2;
constexpr int kCoarseCells = 1 << kCoarseShift;

/// The built grid, by value: sorted sample indices and positions, bucket ranges, and which
/// coarse cells hold a sample (hashed like the buckets: a shared bucket only reads as occupied).
struct HashGridView {
  const uint32_t* cell_start;  ///< first sorted slot of each bucket (start == end: empty)
  const uint32_t* cell_end;    ///< one past the last sorted slot of each bucket
  const uint32_t* sorted_index;  ///< sample index of each sorted slot
  const Vec3* sorted_x;        ///< sample position of each sorted slot (coherent reads)
  int64_t count;               ///< number of samples
  float h;                     ///< cell size, canvas cells
  uint32_t mask;               ///< bucket count - 1 (a power of two)
  const int32_t* bounds;       ///< cell bounding box of the samples: lo x, y, z, hi x, y, z
  const int32_t* coarse;       ///< per bucket of coarse cell (cell >> kCoarseShift): 1 when it may hold a sample
};


/// A cell coordinate defined for every float: beyond +-1e9 cells (no canvas is that large) and
/// for a non-finite value (a point the step's containment is about to remove) it is clamped, as
/// converting such a float to int is undefined.
WB_HD WB_INLINE int hash_coord(float v) {
  if (v > -1e9f && v < 1e9f) return int(floorf(v));
  return v > 0.f ? 1000000000 : -1000000000;
}

/// Integer cell of p for cell size h.
WB_HD WB_INLINE void hash_cell_of(Vec3 p, float inv_h, int& ix, int& iy, int& iz) {
  ix = hash_coord(p.x * inv_h);
  iy = hash_coord(p.y * inv_h);
  iz = hash_coord(p.z * inv_h);
}

/// Bucket of cell (ix, iy, iz): the spatial hash of Teschner et al. 2003, masked. Distinct
/// cells may share a bucket; queries then see extra samples, never miss one.
WB_HD WB_INLINE uint32_t hash_bucket(int ix, int iy, int iz, uint32_t mask) {
  return ((uint32_t(ix) * 73856093u) ^ (uint32_t(iy) * 19349663u) ^ (uint32_t(iz) * 83492791u)) & mask;
}

/// Result of a nearest-sample query.
struct NearestSample {
  int32_t index;  ///< sample index, -1 when none lies within the range
  float dist;     ///< distance to it, or the range when none
};

/// Rings (cells along one axis) from cell c to the nearest cell of [lo, hi]: 0 inside.
WB_HD WB_INLINE int ring_near(int lo, int hi, int c) { return c < lo ? lo - c : (c > hi ? c - hi : 0); }
/// Rings from cell c to the farthest cell of [lo, hi].
WB_HD WB_INLINE int ring_far(int lo, int hi, int c) { return c - lo > hi - c ? c - lo : hi - c; }

/// Visits the cells (cx+dx, cy+dy, cz+dz) on the Chebyshev shell of ring R around (cx, cy, cz),
/// clipped to the box [lo, hi] of absolute cells, and calls fn(x, y, z) for each.
template <class F>
WB_HD WB_INLINE void for_shell(int cx, int cy, int cz, int R, const int lo[3], const int hi[3], F&& fn) {
  const int z0 = imax(-R, lo[2] - cz), z1 = imin(R, hi[2] - cz), y0 = imax(-R, lo[1] - cy), y1 = imin(R, hi[1] - cy);
  const int x0 = imax(-R, lo[0] - cx), x1 = imin(R, hi[0] - cx);
  for (int dz = z0; dz <= z1; ++dz)
    for (int dy = y0; dy <= y1; ++dy) {
      // On the shell's two z faces and two y faces the whole clipped row; inside them
      // only the row's two end cells dx = -R and dx = R lie on the shell.
      const bool face = dz == -R || dz == R || dy == -R || dy == R;
      const int step = face ? 1 : 2 * R;
      for (int dx = face ? x0 : -R; dx <= (face ? x1 : R); dx += step) {
        if (dx < x0 || dx > x1) continue;
        fn(cx + dx, cy + dy, cz + dz);
      }
    }
}

/// Nearest sample to p within max_range. Shells of cells at Chebyshev ring R = 0, 1, ...
/// around p's cell are visited in order, clipped to the samples' cell bounding box and to the
/// cells the cube of half-side max_range around p reaches; after ring R every unvisited sample
/// is farther than R h plus p's distance to the nearest face of its cell, so the search stops
/// once the best distance is below that, R h reaches max_range, or the shell has left the box.
/// Ties go to the lower sample index, so the answer does not depend on the order buckets are
/// visited.
///
/// The rings that hold no sample are skipped first on the coarse occupancy: when the coarse
/// cells within coarse ring K - 1 of p's are all empty, every sample lies at least 4K - 3
/// rings out (a coarse ring spans kCoarseCells rings), and when they are empty out to the
/// coarse ring that reaches max_range there is no answer. Most particles of a stroke lie
/// beyond D1 of every bristle: they pay a few coarse lookups instead of every shell out to
/// D1. Only empty rings are skipped, so the answer is the same.
WB_HD WB_INLINE NearestSample nearest_sample(const HashGridView& g, Vec3 p, float max_range) {
  NearestSample out{-1, max_range};
  if (g.count == 0 || !isfinite3(p)) return out;  // a non-finite point has no neighbour
  const float inv_h = 1.f / g.h;
  int cx, cy, cz;
  hash_cell_of(p, inv_h, cx, cy, cz);
  // Rings of the box's nearest and farthest cells. Each distance is a difference of the two
  // ends taken in the order that makes it non-negative: nvcc 13.0 (sm_90) folded the
  // equivalent nested max(lo, -hi, 0) of the negated differences wrongly (the query then
  // skipped ring 0).
  const int blo[3] = {g.bounds[0], g.bounds[1], g.bounds[2]}, bhi[3] = {g.bounds[3], g.bounds[4], g.bounds[5]};
  // The cells visited: those of the samples' box that the cube of half-side max_range around p
  // reaches (no sample within max_range lies outside it). For a short range this is a few cells
  // of ring 1, not the whole ring.
  const float pc[3] = {p.x, p.y, p.z};
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = imax(blo[a], hash_coord((pc[a] - max_range) * inv_h));
    hi[a] = imin(bhi[a], hash_coord((pc[a] + max_range) * inv_h));
    if (lo[a] > hi[a]) return out;  // no sample's cell within reach
  }
  const int r_box = imax(imax(ring_far(lo[0], hi[0], cx), ring_far(lo[1], hi[1], cy)), ring_far(lo[2], hi[2], cz));
  int r_start = imax(imax(ring_near(lo[0], hi[0], cx), ring_near(lo[1], hi[1], cy)), ring_near(lo[2], hi[2], cz));
  {
    // Coarse rings out to K_max, where 4 K_max h >= max_range: beyond it nothing is in range.
    const int k_max = int(ceilf(max_range * inv_h / float(kCoarseCells)));
    const int ccx = cx >> kCoarseShift, ccy = cy >> kCoarseShift, ccz = cz >> kCoarseShift;
    const int clo[3] = {blo[0] >> kCoarseShift, blo[1] >> kCoarseShift, blo[2] >> kCoarseShift};
    const int chi[3] = {bhi[0] >> kCoarseShift, bhi[1] >> kCoarseShift, bhi[2] >> kCoarseShift};
    int first = -1;
    for (int K = 0; K <= k_max && first < 0; ++K) {
      bool occupied = false;
      for_shell(ccx, ccy, ccz, K, clo, chi, [&](int x, int y, int z) {
        occupied = occupied || g.coarse[hash_bucket(x, y, z, g.mask)] != 0;
      });
      if (occupied) first = K;
    }
    if (first < 0) return out;
    if (first > 0) r_start = imax(r_start, kCoarseCells * first - (kCoarseCells - 1));
  }
  float best_d2 = max_range * max_range;
  int32_t best = -1;
  // After ring R every unvisited cell lies beyond the cube of rings 0..R, at least R h plus
  // p's distance to the nearest face of its own cell away.
  const int cell[3] = {cx, cy, cz};
  float edge = g.h;
  for (int a = 0; a < 3; ++a) {
    const float in_cell = pc[a] - float(cell[a]) * g.h;
    edge = fminf(edge, fminf(in_cell, g.h - in_cell));
  }
  edge = fmaxf(edge - 1e-3f * g.h, 0.f);  // less the round-off of p - c h far from the origin
  // Cells of ring R hold points at distance <= max_range only while (R - 1) h < max_range.
  const int r_max = imin(int(ceilf(max_range * inv_h)) + 1, r_box);
  for (int R = r_start; R <= r_max; ++R) {
    if (R > 0 && float(R - 1) * g.h >= max_range) break;
    for_shell(cx, cy, cz, R, lo, hi, [&](int x, int y, int z) {
      const uint32_t bucket = hash_bucket(x, y, z, g.mask);
      const uint32_t end = g.cell_end[bucket];
      for (uint32_t s = g.cell_start[bucket]; s < end; ++s) {
        const float d2 = length2(g.sorted_x[s] - p);
        if (!(d2 <= best_d2)) continue;  // most samples (and a NaN): one compare, no index read
        const int32_t idx = int32_t(g.sorted_index[s]);
        if (d2 < best_d2 || (best >= 0 && idx < best)) {
          best_d2 = d2;
          best = idx;
        }
      }
    });
    const float reach = float(R) * g.h + edge;
    if (best >= 0 && best_d2 < reach * reach) break;
  }
  if (best >= 0 && best_d2 < max_range * max_range) {
    out.index = best;
    out.dist = sqrtf(best_d2);
  }
  return out;
}

}  // namespace wb
