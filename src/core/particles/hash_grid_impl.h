// Sample hash grid drivers (paper §6, Green 2010), compiled once per backend.
#pragma once
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"
#include "core/particles/hash_grid.h"

namespace wb::WB_BACKEND_NS {

// Position hashed for sample i: x - v rewind_dt (v may be null when rewind_dt is 0).
WB_HD WB_INLINE Vec3 hashed_position(const Vec3* x, const Vec3* v, float rewind_dt, int64_t i) {
  return rewind_dt != 0.f ? x[i] - v[i] * rewind_dt : x[i];
}

void hash_grid_keys(const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, uint32_t mask,
                    uint32_t* keys, uint32_t* index, int32_t* bounds, int32_t* coarse) {
  // Empty box (lo > hi) until the key pass widens it with integer atomics; set on the device,
  // so that the host never waits for an upload.
  parallel_for(1, [=] WB_HD(int64_t) {
    for (int a = 0; a < 3; ++a) {
      bounds[a] = INT32_MAX;
      bounds[3 + a] = INT32_MIN;
    }
  });
  parallel_for(n, [=] WB_HD(int64_t i) {
    int cx, cy, cz;
    hash_cell_of(hashed_position(x, v, rewind_dt, i), inv_h, cx, cy, cz);
    atomic_min(&bounds[0], int32_t(cx));
    atomic_min(&bounds[1], int32_t(cy));
    atomic_min(&bounds[2], int32_t(cz));
    atomic_max(&bounds[3], int32_t(cx));
    atomic_max(&bounds[4], int32_t(cy));
    atomic_max(&bounds[5], int32_t(cz));
    keys[i] = hash_bucket(cx, cy, cz, mask);
    atomic_or(&coarse[hash_bucket(cx >> kCoarseShift, cy >> kCoarseShift, cz >> kCoarseShift, mask)], 1);
    index[i] = uint32_t(i);
  });
}

// Buckets were zeroed (start == end == 0: empty); each run of equal keys marks its ends.
void hash_grid_ranges(const uint32_t* sorted_keys, const uint32_t* index, const Vec3* x, const Vec3* v, float rewind_dt,
                      int64_t n, uint32_t* start, uint32_t* end, Vec3* sorted_x) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const uint32_t k = sorted_keys[i];
    if (i == 0 || sorted_keys[i - 1] != k) start[k] = uint32_t(i);
    if (i == n - 1 || sorted_keys[i + 1] != k) end[k] = uint32_t(i + 1);
    sorted_x[i] = hashed_position(x, v, rewind_dt, int64_t(index[i]));
  });
}

void hash_grid_query(HashGridView g, ParticleView p, float max_range) {
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    const Vec3 x = p.x[k];
    const NearestSample s = nearest_sample(g, x, max_range);
    p.nearest[k] = s.index;
    p.d_B[k] = s.dist;
    int cx, cy, cz;
    hash_cell_of(x, 1.f / g.h, cx, cy, cz);
    p.key[k] = hash_bucket(cx, cy, cz, g.mask);
  });
}

}  // namespace wb::WB_BACKEND_NS
