// Neighbour search between liquid particles and bristle samples (paper §4.3, §6: the
// sorted list of Green 2010). The samples are sorted by their cell in a dense box of cells
// (x fastest), so that the samples of a run of cells along x are one contiguous range of the
// sorted list; a particle finds its nearest sample by visiting shells of cells outwards, a
// shell's rows at a time.
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// The built grid, by value. The box holds the cells [lo, hi] (inclusive, per axis) of the
/// samples filed; cell (x, y, z) of the box is number ((z - lo.z) ny + y - lo.y) nx + x - lo.x,
/// and first[c] is the first sorted slot whose cell is c or later (first[volume] = the samples
/// filed). The samples of cells [c0, c1] are the slots [first[c0], first[c1 + 1]).
struct SampleGridView {
  const uint32_t* first;         ///< per cell of the box, and one past the last
  const uint32_t* sorted_index;  ///< sample index of each sorted slot
  const Vec3* sorted_x;          ///< sample position of each sorted slot (coherent reads)
  int64_t count;                 ///< number of samples filed
  float h;                       ///< cell size, canvas cells
  const int32_t* box;            ///< lo x, y, z, hi x, y, z (cells); lo > hi: no sample
  /// Per coarse cell of the box (kCoarse cells a side, from its lo corner): 1 when a sample may
  /// lie within the query's range of a point in it (the query sets it for its range).
  const uint8_t* near;
};

/// Coarse cells are kCoarse x kCoarse x kCoarse cells of the grid.
constexpr int kCoarseShift = 2;
constexpr int kCoarse = 1 << kCoarseShift;

/// Coarse cells along each axis of a box of n cells.
WB_HD WB_INLINE int coarse_count(int64_t n) { return int((n + kCoarse - 1) >> kCoarseShift); }

/// A cell coordinate defined for every float: beyond +-1e9 cells (no canvas is that large) and
/// for a non-finite value (a point the step's containment is about to remove) it is clamped, as
/// converting such a float to int is undefined.
WB_HD WB_INLINE int cell_coord(float v) {
  if (v > -1e9f && v < 1e9f) return int(floorf(v));
  return v > 0.f ? 1000000000 : -1000000000;
}

/// Integer cell of p for cell size h.
WB_HD WB_INLINE void sample_cell_of(Vec3 p, float inv_h, int& ix, int& iy, int& iz) {
  ix = cell_coord(p.x * inv_h);
  iy = cell_coord(p.y * inv_h);
  iz = cell_coord(p.z * inv_h);
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

/// Checks the sorted slots [s, end) against the best so far (ties to the lower sample index).
WB_HD WB_INLINE void nearest_in(const SampleGridView& g, Vec3 p, uint32_t s, uint32_t end, float& best_d2,
                                int32_t& best) {
  for (; s < end; ++s) {
    const float d2 = length2(g.sorted_x[s] - p);
    if (!(d2 <= best_d2)) continue;  // most samples (and a NaN): one compare, no index read
    const int32_t idx = int32_t(g.sorted_index[s]);
    if (d2 < best_d2 || (best >= 0 && idx < best)) {
      best_d2 = d2;
      best = idx;
    }
  }
}

/// Nearest sample to p within max_range. Shells of cells at Chebyshev ring R = 0, 1, ...
/// around p's cell are visited in order, clipped to the box's cells that the cube of
/// half-side max_range around p reaches; after ring R every unvisited sample is farther than
/// R h plus p's distance to the nearest face of its cell, so the search stops once the best
/// distance is below that or R h reaches max_range. A shell's cells lie in rows along x: on its
/// two z faces and two y faces whole rows, each one range of the sorted list (two loads for
/// up to 2R + 1 cells); inside them the rows' two end cells. Ties go to the lower sample index,
/// so the answer does not depend on the order of the visits.
///
/// Most particles of a stroke lie beyond the range of every sample: the coarse cell's flag
/// (SampleGridView::near) tells them with one load.
WB_HD WB_INLINE NearestSample nearest_sample(const SampleGridView& g, Vec3 p, float max_range) {
  NearestSample out{-1, max_range};
  if (g.count == 0 || !isfinite3(p)) return out;  // a non-finite point has no neighbour
  const float inv_h = 1.f / g.h;
  const int blo[3] = {g.box[0], g.box[1], g.box[2]}, bhi[3] = {g.box[3], g.box[4], g.box[5]};
  const float pc[3] = {p.x, p.y, p.z};
  // The cells visited: those of the box that the cube of half-side max_range around p reaches
  // (no sample within max_range lies outside it). For a short range this is a few cells of
  // ring 1, not the whole ring.
  int lo[3], hi[3], c[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = imax(blo[a], cell_coord((pc[a] - max_range) * inv_h));
    hi[a] = imin(bhi[a], cell_coord((pc[a] + max_range) * inv_h));
    if (lo[a] > hi[a]) return out;  // no sample's cell within reach
    c[a] = cell_coord(pc[a] * inv_h);
  }
  const int64_t nx = int64_t(bhi[0]) - blo[0] + 1, ny = int64_t(bhi[1]) - blo[1] + 1;
  if (c[0] >= blo[0] && c[0] <= bhi[0] && c[1] >= blo[1] && c[1] <= bhi[1] && c[2] >= blo[2] && c[2] <= bhi[2]) {
    // p's coarse cell (a point outside the box goes on to the shells).
    const int64_t cc = (int64_t((c[2] - blo[2]) >> kCoarseShift) * coarse_count(ny) + ((c[1] - blo[1]) >> kCoarseShift)) *
                           coarse_count(nx) +
                       ((c[0] - blo[0]) >> kCoarseShift);
    if (!g.near[cc]) return out;
  }
  // Rings of the nearest and farthest cells visited. Each distance is a difference of the two
  // ends taken in the order that makes it non-negative: nvcc 13.0 (sm_90) folded the
  // equivalent nested max(lo, -hi, 0) of the negated differences wrongly (the query then
  // skipped ring 0).
  const int r_box = imax(imax(ring_far(lo[0], hi[0], c[0]), ring_far(lo[1], hi[1], c[1])), ring_far(lo[2], hi[2], c[2]));
  const int r_start = imax(imax(ring_near(lo[0], hi[0], c[0]), ring_near(lo[1], hi[1], c[1])), ring_near(lo[2], hi[2], c[2]));
  // After ring R every unvisited cell lies beyond the cube of rings 0..R, at least R h plus
  // p's distance to the nearest face of its own cell away.
  float edge = g.h;
  for (int a = 0; a < 3; ++a) {
    const float in_cell = pc[a] - float(c[a]) * g.h;
    edge = fminf(edge, fminf(in_cell, g.h - in_cell));
  }
  edge = fmaxf(edge - 1e-3f * g.h, 0.f);  // less the round-off of p - c h far from the origin
  float best_d2 = max_range * max_range;
  int32_t best = -1;
  // Cells of ring R hold points at distance <= max_range only while (R - 1) h < max_range.
  const int r_max = imin(int(ceilf(max_range * inv_h)) + 1, r_box);
  for (int R = r_start; R <= r_max; ++R) {
    if (R > 0 && float(R - 1) * g.h >= max_range) break;
    const int z0 = imax(c[2] - R, lo[2]), z1 = imin(c[2] + R, hi[2]), y0 = imax(c[1] - R, lo[1]);
    const int y1 = imin(c[1] + R, hi[1]), x0 = imax(c[0] - R, lo[0]), x1 = imin(c[0] + R, hi[0]);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) {
        const int64_t row = ((int64_t(z) - blo[2]) * ny + (int64_t(y) - blo[1])) * nx - blo[0];
        if (z == c[2] - R || z == c[2] + R || y == c[1] - R || y == c[1] + R) {
          if (x0 <= x1) nearest_in(g, p, g.first[row + x0], g.first[row + x1 + 1], best_d2, best);
        } else {
          // Inside the shell's faces only the row's two end cells lie on the shell.
          if (c[0] - R >= lo[0]) nearest_in(g, p, g.first[row + c[0] - R], g.first[row + c[0] - R + 1], best_d2, best);
          if (c[0] + R <= hi[0]) nearest_in(g, p, g.first[row + c[0] + R], g.first[row + c[0] + R + 1], best_d2, best);
        }
      }
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
