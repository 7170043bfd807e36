// Sample hash grid drivers (paper §6, Green 2010), compiled once per backend.
#pragma once
#include "core/exec/parallel_for.h"
#include "core/particles/hash_grid.h"

namespace wb::WB_BACKEND_NS {

void hash_grid_keys(const Vec3* x, int64_t n, float inv_h, uint32_t mask, uint32_t* keys, uint32_t* index) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    int cx, cy, cz;
    hash_cell_of(x[i], inv_h, cx, cy, cz);
    keys[i] = hash_bucket(cx, cy, cz, mask);
    index[i] = uint32_t(i);
  });
}

// Buckets were zeroed (start == end == 0: empty); each run of equal keys marks its ends.
void hash_grid_ranges(const uint32_t* sorted_keys, const uint32_t* index, const Vec3* x, int64_t n, uint32_t* start,
                      uint32_t* end, Vec3* sorted_x) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const uint32_t k = sorted_keys[i];
    if (i == 0 || sorted_keys[i - 1] != k) start[k] = uint32_t(i);
    if (i == n - 1 || sorted_keys[i + 1] != k) end[k] = uint32_t(i + 1);
    sorted_x[i] = x[index[i]];
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
