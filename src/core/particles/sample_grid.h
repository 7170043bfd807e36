// Sample grid (paper §6, Green 2010): built from the bristle samples every step, queried
// from the particles for the nearest sample and the distance to it, within the range its user
// needs (d_B of Eq. 10 within D1; Eq. 14's absorber within the load sphere). "Within D0" of
// §5.2 is the coarse distance field of the transfer stage, not this query. The samples are
// sorted by their cell in the dense box of cells they occupy (within the region the queries
// ask about), so that a run of cells along x is one range of the sorted list (docs/PARTICLES.md
// "Nearest sample"). Four launches to build: the box, the keys, a radix sort, each cell's
// first slot with the sorted positions.
#pragma once
#include <cstdint>

#include "core/brush/bristle_fields.h"
#include "core/exec/buffer.h"
#include "core/exec/device.h"
#include "core/exec/dispatch.h"
#include "core/exec/workspace.h"
#include "core/particles/sample_grid_kernels.h"
#include "core/particles/particle_fields.h"

namespace wb {

/// A box of grid cells, inclusive: lo[a] <= cell <= hi[a] along each axis.
struct CellBox {
  int32_t lo[3], hi[3];
};

class SampleGrid {
 public:
  SampleGrid() = default;
  explicit SampleGrid(const Device& device);

  /// Files the samples that lie in `region` (canvas cells, lo to hi) into cells of size
  /// cell_size (canvas cells), at x - v rewind_dt. The region is where the queries' points lie,
  /// grown by their range: a query then sees every sample within its range, and the grid's
  /// memory is bounded by the region's cells whatever the samples do (the simulator's: the
  /// window, where the particles live). The brush step runs first, so its samples hold t + dt
  /// while the particles are still at t: the simulator passes the step's dt to compare both
  /// at t (the frame Eq. 9 starts from, see local_frame_step); 0 files x as it is. Buffers
  /// grow geometrically and are kept: no allocation once warm.
  void build(const SampleView& samples, float cell_size, Vec3 region_lo, Vec3 region_hi, Workspace& ws,
             float rewind_dt = 0.f);
  /// For every particle: nearest = nearest sample within max_range (-1: none), d_B = its
  /// distance (max_range when none). Exact for a particle whose range lies in the region; one
  /// beyond sees only the region's samples.
  void query_nearest(const ParticleView& particles, float max_range);

  SampleGridView view() const;
  const Device& device() const { return device_; }
  int64_t sample_count() const { return count_; }
  /// Cells the last build could use (the region's), the size of its cell table less one.
  int64_t cell_capacity() const { return capacity_; }

 private:
  Device device_;
  int64_t count_ = 0;
  float h_ = 1.f;
  int64_t capacity_ = 0, coarse_capacity_ = 0;
  DeviceBuffer<uint32_t> keys_, index_, first_;
  DeviceBuffer<uint8_t> occupied_, near_;  ///< per coarse cell: holds a sample; one within the range
  DeviceBuffer<Vec3> sorted_x_;
  DeviceBuffer<int32_t> box_;  ///< the cells of the samples in the region
};

/// Reference for tests: the nearest sample to p among all n (host arrays), within max_range.
NearestSample nearest_sample_brute_force(const Vec3* samples, int64_t n, Vec3 p, float max_range);

// The sample grid's backend drivers (sample_grid_impl.h), one list (core/exec/dispatch.h).
#define WB_SAMPLE_GRID_KERNELS(X)                                                                                   \
  X(void, sample_grid_box, (const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, CellBox region,  \
      int32_t* box), (x, v, rewind_dt, n, inv_h, region, box))                                                      \
  X(void, sample_grid_keys, (const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, CellBox region, \
      const int32_t* box, uint32_t* keys, uint32_t* index), (x, v, rewind_dt, n, inv_h, region, box, keys, index))  \
  X(void, sample_grid_first, (const uint32_t* sorted_keys, const uint32_t* index, const Vec3* x, const Vec3* v,     \
      float rewind_dt, int64_t n, const int32_t* box, uint32_t* first, Vec3* sorted_x),                             \
      (sorted_keys, index, x, v, rewind_dt, n, box, first, sorted_x))                                               \
  X(void, sample_grid_coarse, (const int32_t* box, const uint32_t* first, int64_t capacity, uint8_t* occupied),     \
      (box, first, capacity, occupied))                                                                             \
  X(void, sample_grid_near, (const int32_t* box, const uint8_t* occupied, int reach, int64_t capacity,              \
      uint8_t* near), (box, occupied, reach, capacity, near))                                                       \
  X(void, sample_grid_query, (SampleGridView g, ParticleView p, float max_range), (g, p, max_range))
WB_DECLARE_KERNELS(WB_SAMPLE_GRID_KERNELS)

}  // namespace wb
