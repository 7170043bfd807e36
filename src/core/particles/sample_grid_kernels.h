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

/// Rings (cells along one axis) from the cells [b0, b1] to the nearest cell of [lo, hi]: 0 where
/// they overlap.
WB_HD WB_INLINE int ring_near(int lo, int hi, int b0, int b1) { return b1 < lo ? lo - b1 : (b0 > hi ? b0 - hi : 0); }
/// Rings from the cells [b0, b1] to the farthest cell of [lo, hi].
WB_HD WB_INLINE int ring_far(int lo, int hi, int b0, int b1) { return imax(imax(b0 - lo, hi - b1), 0); }

/// Distance along one axis from cell i's slab [i h, (i + 1) h] to the span [a, b] of points, 0
/// where they overlap, less a thousandth of a cell for the round-off of i h far from the origin.
WB_HD WB_INLINE float gap_to_span(int i, float a, float b, float h) {
  return maxf(maxf(float(i) * h - b, a - float(i + 1) * h) - 1e-3f * h, 0.f);
}

/// Points a nearest-sample query takes together: on the CPU 16 consecutive particles (sorted by
/// cell, they are neighbours), which read each row of the sorted list once for all and test each
/// sample against all of them in vector lanes; on CUDA 1, a warp's threads being the lanes.
#if defined(__CUDACC__)
inline constexpr int kQueryLanes = 1;
#else
inline constexpr int kQueryLanes = 16;
#endif
/// Fewer neighbours than this are queried one at a time: a lane's branch-free test costs a few
/// times the single query's one compare a sample, and a few lanes' shared walk reads more samples
/// than each one's.
inline constexpr int kQueryMinLanes = 4;

/// The points of one query that take part, one lane each.
struct QueryLanes {
  int n;                       ///< lanes in use
  int slot[kQueryLanes];       ///< the point's place among the query's points
  float x[kQueryLanes], y[kQueryLanes], z[kQueryLanes];
  float best_d2[kQueryLanes];  ///< squared distance of the best sample so far
  int32_t best[kQueryLanes];   ///< its index, INT32_MAX while none
  float edge[kQueryLanes];     ///< distance to the nearest face of the query's cells
};

/// Tests the sorted slots [s, end) against every lane: the nearer sample wins, and of two as near
/// the lower index, so that the answer does not depend on the order of the visits.
WB_HD WB_INLINE void nearest_in(const SampleGridView& g, uint32_t s, uint32_t end, QueryLanes& q) {
  if (q.n == 1) {  // one point (always on CUDA): most samples cost one compare, no index read
    const Vec3 p(q.x[0], q.y[0], q.z[0]);
    for (; s < end; ++s) {
      const float d2 = length2(g.sorted_x[s] - p);
      if (!(d2 <= q.best_d2[0])) continue;  // and a NaN
      const int32_t idx = int32_t(g.sorted_index[s]);
      if (d2 < q.best_d2[0] || idx < q.best[0]) {
        q.best_d2[0] = d2;
        q.best[0] = idx;
      }
    }
    return;
  }
  for (; s < end; ++s) {
    const Vec3 v = g.sorted_x[s];
    const int32_t idx = int32_t(g.sorted_index[s]);
    for (int j = 0; j < q.n; ++j) {  // no branch: the lanes vectorise
      const float dx = v.x - q.x[j], dy = v.y - q.y[j], dz = v.z - q.z[j];
      const float d2 = dx * dx + dy * dy + dz * dz;  // length2's order of sums
      const bool better = (d2 < q.best_d2[j]) | ((d2 == q.best_d2[j]) & (idx < q.best[j]));
      q.best_d2[j] = better ? d2 : q.best_d2[j];
      q.best[j] = better ? idx : q.best[j];
    }
  }
}

/// Nearest sample within max_range to each of the points p[0 .. m) (m <= kQueryLanes), written to
/// out. The points' cells span at most two cells along each axis (the caller groups them so), the
/// box B of cells. Shells of cells at Chebyshev ring R = 0, 1, ... around B are visited in order,
/// clipped to the grid's box and to the cells that the cube of half-side max_range around the
/// points reaches; after ring R every unvisited sample is farther from a point than R h plus the
/// point's distance to the nearest face of B, so the search stops once every point's best
/// distance is below that, or R h reaches max_range. A shell's cells lie in rows along x: on its
/// two z faces and two y faces whole rows, each one range of the sorted list (two loads for up to
/// 2R + |B| cells); inside them the rows' two end cells.
///
/// Most particles of a stroke lie beyond the range of every sample: a point's coarse cell flag
/// (SampleGridView::near) tells it with one load, and it takes no part.
WB_HD WB_INLINE void nearest_samples(const SampleGridView& g, const Vec3* p, int m, float max_range,
                                     NearestSample* out) {
  const float inv_h = 1.f / g.h;
  const int blo[3] = {g.box[0], g.box[1], g.box[2]}, bhi[3] = {g.box[3], g.box[4], g.box[5]};
  const int64_t nx = int64_t(bhi[0]) - blo[0] + 1, ny = int64_t(bhi[1]) - blo[1] + 1;
  QueryLanes q;
  q.n = 0;
  int b0[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, b1[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  float p0[3] = {INFINITY, INFINITY, INFINITY}, p1[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int j = 0; j < m; ++j) {
    out[j] = NearestSample{-1, max_range};
    if (g.count == 0 || !isfinite3(p[j])) continue;  // a non-finite point has no neighbour
    const float pc[3] = {p[j].x, p[j].y, p[j].z};
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = cell_coord(pc[a] * inv_h);
    if (c[0] >= blo[0] && c[0] <= bhi[0] && c[1] >= blo[1] && c[1] <= bhi[1] && c[2] >= blo[2] && c[2] <= bhi[2]) {
      // The point's coarse cell (a point outside the box goes on to the shells).
      const int64_t cc = (int64_t((c[2] - blo[2]) >> kCoarseShift) * coarse_count(ny) + ((c[1] - blo[1]) >> kCoarseShift)) *
                             coarse_count(nx) +
                         ((c[0] - blo[0]) >> kCoarseShift);
      if (!g.near[cc]) continue;
    }
    const int l = q.n++;
    q.slot[l] = j;
    q.x[l] = pc[0];
    q.y[l] = pc[1];
    q.z[l] = pc[2];
    q.best_d2[l] = max_range * max_range;
    q.best[l] = INT32_MAX;
    for (int a = 0; a < 3; ++a) {
      b0[a] = imin(b0[a], c[a]);
      b1[a] = imax(b1[a], c[a]);
      p0[a] = minf(p0[a], pc[a]);
      p1[a] = maxf(p1[a], pc[a]);
    }
  }
  if (q.n == 0) return;
  // The cells visited: those of the box that the cubes of half-side max_range around the points
  // reach (no sample within max_range lies outside them).
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = imax(blo[a], cell_coord((p0[a] - max_range) * inv_h));
    hi[a] = imin(bhi[a], cell_coord((p1[a] + max_range) * inv_h));
    if (lo[a] > hi[a]) return;  // no sample's cell within reach
  }
  // Rings of the nearest and farthest cells visited. Each distance is a difference of the two
  // ends taken in the order that makes it non-negative: nvcc 13.0 (sm_90) folded the
  // equivalent nested max(lo, -hi, 0) of the negated differences wrongly (the query then
  // skipped ring 0).
  const int r_box = imax(imax(ring_far(lo[0], hi[0], b0[0], b1[0]), ring_far(lo[1], hi[1], b0[1], b1[1])),
                         ring_far(lo[2], hi[2], b0[2], b1[2]));
  const int r_start = imax(imax(ring_near(lo[0], hi[0], b0[0], b1[0]), ring_near(lo[1], hi[1], b0[1], b1[1])),
                           ring_near(lo[2], hi[2], b0[2], b1[2]));
  // After ring R every unvisited cell lies beyond the cells of rings 0..R, at least R h plus the
  // point's distance to the nearest face of B away; less the round-off of p - c h far from the
  // origin.
  for (int j = 0; j < q.n; ++j) {
    const float pc[3] = {q.x[j], q.y[j], q.z[j]};
    float e = INFINITY;
    for (int a = 0; a < 3; ++a) e = minf(e, minf(pc[a] - float(b0[a]) * g.h, float(b1[a] + 1) * g.h - pc[a]));
    q.edge[j] = maxf(e - 1e-3f * g.h, 0.f);
  }
  // Cells of ring R hold points at distance <= max_range only while (R - 1) h < max_range.
  const int r_max = imin(int(ceilf(max_range * inv_h)) + 1, r_box);
  for (int R = r_start; R <= r_max; ++R) {
    if (R > 0 && float(R - 1) * g.h >= max_range) break;
    const int z0 = imax(b0[2] - R, lo[2]), z1 = imin(b1[2] + R, hi[2]), y0 = imax(b0[1] - R, lo[1]);
    const int y1 = imin(b1[1] + R, hi[1]), x0 = imax(b0[0] - R, lo[0]), x1 = imin(b1[0] + R, hi[0]);
    // A query of several points reads only the rows, and the cells of a row, nearer to the
    // points' box than the farthest of their best distances so far (ties kept: `>`); its lanes
    // share the arithmetic. A single point's walk is cheaper without it (most rows hold nothing).
    const bool cull = q.n > 1;
    float far2 = 0.f;
    for (int j = 0; j < q.n; ++j) far2 = maxf(far2, q.best_d2[j]);
    for (int z = z0; z <= z1; ++z) {
      const float gz = cull ? gap_to_span(z, p0[2], p1[2], g.h) : 0.f;
      for (int y = y0; y <= y1; ++y) {
        float off2 = 0.f;
        if (cull) {
          const float gy = gap_to_span(y, p0[1], p1[1], g.h);
          off2 = gz * gz + gy * gy;
          if (off2 > far2) continue;
        }
        const int64_t row = ((int64_t(z) - blo[2]) * ny + (int64_t(y) - blo[1])) * nx - blo[0];
        if (R == 0 || z == b0[2] - R || z == b1[2] + R || y == b0[1] - R || y == b1[1] + R) {
          int xa = x0, xb = x1;
          if (cull) {
            const float half = sqrtf(far2 - off2) + 1e-3f * g.h;  // and the round-off along x
            xa = imax(xa, cell_coord((p0[0] - half) * inv_h));
            xb = imin(xb, cell_coord((p1[0] + half) * inv_h));
          }
          if (xa <= xb) nearest_in(g, g.first[row + xa], g.first[row + xb + 1], q);
        } else {
          // Inside the shell's faces only the row's two end cells lie on the shell.
          const int xa = b0[0] - R, xb = b1[0] + R;
          auto near_cell = [&](int x) {
            const float gx = gap_to_span(x, p0[0], p1[0], g.h);
            return !cull || off2 + gx * gx <= far2;
          };
          if (xa >= lo[0] && near_cell(xa)) nearest_in(g, g.first[row + xa], g.first[row + xa + 1], q);
          if (xb <= hi[0] && near_cell(xb)) nearest_in(g, g.first[row + xb], g.first[row + xb + 1], q);
        }
      }
    }
    bool done = true;
    for (int j = 0; j < q.n; ++j) {
      const float reach = float(R) * g.h + q.edge[j];
      done = done && q.best[j] != INT32_MAX && q.best_d2[j] < reach * reach;
    }
    if (done) break;
  }
  for (int j = 0; j < q.n; ++j)
    if (q.best[j] != INT32_MAX && q.best_d2[j] < max_range * max_range)
      out[q.slot[j]] = NearestSample{q.best[j], sqrtf(q.best_d2[j])};
}

/// Whether a point in cell c may join a query whose cells are [b0, b1]: the query's cells then
/// span at most two along each axis.
WB_HD WB_INLINE bool query_joins(const int* b0, const int* b1, const int* c) {
  for (int a = 0; a < 3; ++a)
    if (imax(b1[a], c[a]) - imin(b0[a], c[a]) > 1) return false;
  return true;
}

}  // namespace wb
