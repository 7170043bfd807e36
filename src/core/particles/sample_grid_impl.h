// Sample grid drivers (paper §6, Green 2010), compiled once per backend.
#pragma once
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"
#include "core/particles/sample_grid.h"

namespace wb::WB_BACKEND_NS {

// Position filed for sample i: x - v rewind_dt (v may be null when rewind_dt is 0).
WB_HD WB_INLINE Vec3 filed_position(const Vec3* x, const Vec3* v, float rewind_dt, int64_t i) {
  return rewind_dt != 0.f ? x[i] - v[i] * rewind_dt : x[i];
}

// Cells in the box (lo > hi on some axis: none).
WB_HD WB_INLINE int64_t box_volume(const int32_t* box) {
  int64_t v = 1;
  for (int a = 0; a < 3; ++a) v *= box[a] <= box[3 + a] ? int64_t(box[3 + a]) - box[a] + 1 : 0;
  return v;
}

WB_HD WB_INLINE bool in_region(const CellBox& r, int cx, int cy, int cz) {
  return cx >= r.lo[0] && cx <= r.hi[0] && cy >= r.lo[1] && cy <= r.hi[1] && cz >= r.lo[2] && cz <= r.hi[2];
}

void sample_grid_box(const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, CellBox region,
                     int32_t* box) {
  // Empty box (lo > hi) until the samples in the region widen it with integer atomics; set on
  // the device, so that the host never waits for an upload.
  parallel_for(1, [=] WB_HD(int64_t) {
    for (int a = 0; a < 3; ++a) {
      box[a] = INT32_MAX;
      box[3 + a] = INT32_MIN;
    }
  });
  parallel_for(n, [=] WB_HD(int64_t i) {
    int cx, cy, cz;
    sample_cell_of(filed_position(x, v, rewind_dt, i), inv_h, cx, cy, cz);
    if (!in_region(region, cx, cy, cz)) return;
    atomic_min(&box[0], int32_t(cx));
    atomic_min(&box[1], int32_t(cy));
    atomic_min(&box[2], int32_t(cz));
    atomic_max(&box[3], int32_t(cx));
    atomic_max(&box[4], int32_t(cy));
    atomic_max(&box[5], int32_t(cz));
  });
}

void sample_grid_keys(const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, CellBox region,
                      const int32_t* box, uint32_t* keys, uint32_t* index) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    int cx, cy, cz;
    sample_cell_of(filed_position(x, v, rewind_dt, i), inv_h, cx, cy, cz);
    // A sample outside the region takes the key one past the box's cells: it sorts last and
    // no cell's range holds it.
    const int64_t nx = int64_t(box[3]) - box[0] + 1, ny = int64_t(box[4]) - box[1] + 1;
    keys[i] = in_region(region, cx, cy, cz)
                  ? uint32_t(((int64_t(cz) - box[2]) * ny + (int64_t(cy) - box[1])) * nx + (int64_t(cx) - box[0]))
                  : uint32_t(box_volume(box));
    index[i] = uint32_t(i);
  });
}

// After the sort: slot i is the first of every cell after slot i - 1's and up to its own (the
// box's end for i = n), so each cell's entry is written once, with no clearing beforehand.
void sample_grid_first(const uint32_t* sorted_keys, const uint32_t* index, const Vec3* x, const Vec3* v,
                       float rewind_dt, int64_t n, const int32_t* box, uint32_t* first, Vec3* sorted_x) {
  parallel_for(n + 1, [=] WB_HD(int64_t i) {
    const int64_t volume = box_volume(box);
    const int64_t prev = i == 0 ? -1 : int64_t(sorted_keys[i - 1]);
    const int64_t cur = i == n ? volume : int64_t(sorted_keys[i]);
    for (int64_t c = prev + 1; c <= cur; ++c) first[c] = uint32_t(i);
    if (i < n) sorted_x[i] = filed_position(x, v, rewind_dt, int64_t(index[i]));
  });
}

// Coarse cell cc of the box holds a sample: any of its rows has a non-empty range.
void sample_grid_coarse(const int32_t* box, const uint32_t* first, int64_t capacity, uint8_t* occupied) {
  parallel_for(capacity, [=] WB_HD(int64_t cc) {
    if (box_volume(box) == 0) return;
    const int64_t nx = int64_t(box[3]) - box[0] + 1, ny = int64_t(box[4]) - box[1] + 1, nz = int64_t(box[5]) - box[2] + 1;
    const int cnx = coarse_count(nx), cny = coarse_count(ny), cnz = coarse_count(nz);
    if (cc >= int64_t(cnx) * cny * cnz) return;
    const int64_t ci = cc % cnx, cj = (cc / cnx) % cny, ck = cc / (int64_t(cnx) * cny);
    const int64_t x0 = ci * kCoarse, x1 = x0 + kCoarse < nx ? x0 + kCoarse : nx;
    uint8_t any = 0;
    for (int64_t k = ck * kCoarse; k < (ck + 1) * kCoarse && k < nz && !any; ++k)
      for (int64_t j = cj * kCoarse; j < (cj + 1) * kCoarse && j < ny && !any; ++j) {
        const int64_t row = (k * ny + j) * nx;
        any = first[row + x0] < first[row + x1];
      }
    occupied[cc] = any;
  });
}

// Coarse cell cc is near when a coarse cell within `reach` of it (Chebyshev) holds a sample.
void sample_grid_near(const int32_t* box, const uint8_t* occupied, int reach, int64_t capacity, uint8_t* near) {
  parallel_for(capacity, [=] WB_HD(int64_t cc) {
    if (box_volume(box) == 0) return;
    const int cnx = coarse_count(int64_t(box[3]) - box[0] + 1), cny = coarse_count(int64_t(box[4]) - box[1] + 1);
    const int cnz = coarse_count(int64_t(box[5]) - box[2] + 1);
    if (cc >= int64_t(cnx) * cny * cnz) return;
    const int ci = int(cc % cnx), cj = int((cc / cnx) % cny), ck = int(cc / (int64_t(cnx) * cny));
    uint8_t any = 0;
    for (int k = imax(ck - reach, 0); k <= imin(ck + reach, cnz - 1) && !any; ++k)
      for (int j = imax(cj - reach, 0); j <= imin(cj + reach, cny - 1) && !any; ++j)
        for (int i = imax(ci - reach, 0); i <= imin(ci + reach, cnx - 1) && !any; ++i)
          any = occupied[(int64_t(k) * cny + j) * cnx + i];
    near[cc] = any;
  });
}

void sample_grid_query(SampleGridView g, ParticleView p, float max_range) {
  // Runs of kQueryLanes particles; of a run, each stretch whose cells span at most two a side is
  // one query (the particles are sorted by cell: most runs are one or two).
  parallel_for_runs<kQueryLanes>(p.count, [=] WB_HD(int64_t k0, int lanes) {
    // Neighbours on a lattice of at most 2-cell cells (the default grid's): on a coarser grid
    // two of its cells would hold points too far apart to share much of their walk.
    const float inv_h = 1.f / minf(g.h, 2.f);
    NearestSample found[kQueryLanes];
    int start = 0, b0[3] = {0, 0, 0}, b1[3] = {0, 0, 0};
    for (int j = 0; j <= lanes; ++j) {
      int c[3] = {0, 0, 0};
      if (j < lanes) sample_cell_of(p.x[k0 + j], inv_h, c[0], c[1], c[2]);
      if (j > start && (j == lanes || !query_joins(b0, b1, c))) {
        if (j - start >= kQueryMinLanes) {
          nearest_samples(g, p.x + k0 + start, j - start, max_range, found + start);
        } else {  // too few to share the walk: one at a time, one compare a sample
          for (int i = start; i < j; ++i) nearest_samples(g, p.x + k0 + i, 1, max_range, found + i);
        }
        start = j;
      }
      if (j == start)
        for (int a = 0; a < 3; ++a) b0[a] = b1[a] = c[a];
      for (int a = 0; a < 3; ++a) {
        b0[a] = imin(b0[a], c[a]);
        b1[a] = imax(b1[a], c[a]);
      }
    }
    for (int j = 0; j < lanes; ++j) {
      p.nearest[k0 + j] = found[j].index;
      p.d_B[k0 + j] = found[j].dist;
    }
  });
}

}  // namespace wb::WB_BACKEND_NS
