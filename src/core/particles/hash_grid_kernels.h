// Neighbour search between liquid particles and bristle samples (paper §4.3, §6: the
// sorted hash list of Green 2010). Samples are hashed into a uniform grid of cells;
// after a radix sort by bucket each bucket is a contiguous range [start, end). A
// particle finds its nearest sample by visiting shells of cells outwards.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// The built grid, by value: sorted sample indices and positions, bucket ranges.
struct HashGridView {
  const uint32_t* cell_start;  ///< first sorted slot of each bucket (start == end: empty)
  const uint32_t* cell_end;    ///< one past the last sorted slot of each bucket
  const uint32_t* sorted_index;  ///< sample index of each sorted slot
  const Vec3* sorted_x;        ///< sample position of each sorted slot (coherent reads)
  int64_t count;               ///< number of samples
  float h;                     ///< cell size, canvas cells
  uint32_t mask;               ///< bucket count - 1 (a power of two)
  const int32_t* bounds;       ///< cell bounding box of the samples: lo x, y, z, hi x, y, z
};

WB_HD WB_INLINE int imax(int a, int b) { return a > b ? a : b; }
WB_HD WB_INLINE int imin(int a, int b) { return a < b ? a : b; }

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

/// Nearest sample to p within max_range. Shells of cells at Chebyshev ring R = 0, 1, ...
/// around p's cell are visited in order, clipped to the samples' cell bounding box; after
/// ring R every unvisited sample is farther than R h, so the search stops once the best
/// distance is below R h, R h reaches max_range, or the shell has left the box. Ties go to
/// the lower sample index, so the answer does not depend on the order buckets are visited.
WB_HD WB_INLINE NearestSample nearest_sample(const HashGridView& g, Vec3 p, float max_range) {
  NearestSample out{-1, max_range};
  if (g.count == 0 || !isfinite3(p)) return out;  // a non-finite point has no neighbour
  const float inv_h = 1.f / g.h;
  int cx, cy, cz;
  hash_cell_of(p, inv_h, cx, cy, cz);
  // Box of sample cells relative to p's cell, and the Chebyshev rings of its nearest and
  // farthest cells. Each distance is a difference of the two ends taken in the order that
  // makes it non-negative: nvcc 13.0 (sm_90) folded the equivalent nested
  // max(lo, -hi, 0) of the negated differences wrongly (the query then skipped ring 0).
  const int lx = g.bounds[0] - cx, ly = g.bounds[1] - cy, lz = g.bounds[2] - cz;
  const int hx = g.bounds[3] - cx, hy = g.bounds[4] - cy, hz = g.bounds[5] - cz;
  const int r_box = imax(imax(ring_far(g.bounds[0], g.bounds[3], cx), ring_far(g.bounds[1], g.bounds[4], cy)),
                         ring_far(g.bounds[2], g.bounds[5], cz));
  const int r_near = imax(imax(ring_near(g.bounds[0], g.bounds[3], cx), ring_near(g.bounds[1], g.bounds[4], cy)),
                          ring_near(g.bounds[2], g.bounds[5], cz));
  float best_d2 = max_range * max_range;
  int32_t best = -1;
  // Cells of ring R hold points at distance <= max_range only while (R - 1) h < max_range.
  const int r_max = imin(int(ceilf(max_range * inv_h)) + 1, r_box);
  for (int R = r_near; R <= r_max; ++R) {
    if (R > 0 && float(R - 1) * g.h >= max_range) break;
    const int z0 = imax(-R, lz), z1 = imin(R, hz), y0 = imax(-R, ly), y1 = imin(R, hy);
    const int x0 = imax(-R, lx), x1 = imin(R, hx);
    for (int dz = z0; dz <= z1; ++dz)
      for (int dy = y0; dy <= y1; ++dy) {
        // On the shell's two z faces and two y faces the whole clipped row; inside them
        // only the row's two end cells dx = -R and dx = R lie on the shell.
        const bool face = dz == -R || dz == R || dy == -R || dy == R;
        const int step = face ? 1 : 2 * R;
        for (int dx = face ? x0 : -R; dx <= (face ? x1 : R); dx += step) {
          if (dx < x0 || dx > x1) continue;
          const uint32_t bucket = hash_bucket(cx + dx, cy + dy, cz + dz, g.mask);
          const uint32_t end = g.cell_end[bucket];
          for (uint32_t s = g.cell_start[bucket]; s < end; ++s) {
            const float d2 = length2(g.sorted_x[s] - p);
            const int32_t idx = int32_t(g.sorted_index[s]);
            if (d2 < best_d2 || (d2 == best_d2 && best >= 0 && idx < best)) {
              best_d2 = d2;
              best = idx;
            }
          }
        }
      }
    const float reach = float(R) * g.h;
    if (best >= 0 && best_d2 < reach * reach) break;
  }
  if (best >= 0 && best_d2 < max_range * max_range) {
    out.index = best;
    out.dist = sqrtf(best_d2);
  }
  return out;
}

}  // namespace wb
