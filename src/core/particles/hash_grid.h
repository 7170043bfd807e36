// Sample hash grid (paper §6, Green 2010): built from the bristle samples every step,
// queried from the particles for the nearest sample and the distance to it, within the
// range its user needs (d_B of Eq. 10 within D1; Eq. 14's absorber within the load sphere).
// "Within D0" of §5.2 is the coarse distance field of the transfer stage, not this query.
// Three launches to build: bucket keys (and the coarse occupancy), radix sort, bucket ranges;
// one to gather the sorted positions.
#pragma once
#include <cstdint>

#include "core/brush/bristle_fields.h"
#include "core/exec/buffer.h"
#include "core/exec/device.h"
#include "core/exec/workspace.h"
#include "core/particles/hash_grid_kernels.h"
#include "core/particles/particle_fields.h"

namespace wb {

class SampleHashGrid {
 public:
  SampleHashGrid() = default;
  explicit SampleHashGrid(const Device& device);

  /// Hashes the samples into cells of size cell_size (canvas cells), at x - v rewind_dt.
  /// The brush step runs first, so its samples hold t + dt while the particles are still at
  /// t: the simulator passes the step's dt to compare both at t (the frame Eq. 9 starts
  /// from, see local_frame_step); 0 hashes x as it is. Buffers grow geometrically and are
  /// kept: no allocation once warm.
  void build(const SampleView& samples, float cell_size, Workspace& ws, float rewind_dt = 0.f);
  /// For every particle: nearest = nearest sample within max_range (-1: none), d_B = its
  /// distance (max_range when none), key = the particle's bucket.
  void query_nearest(const ParticleView& particles, float max_range) const;

  HashGridView view() const;
  const Device& device() const { return device_; }
  int64_t sample_count() const { return count_; }
  uint32_t bucket_count() const { return mask_ + 1; }

 private:
  Device device_;
  int64_t count_ = 0;
  float h_ = 1.f;
  uint32_t mask_ = 0;
  DeviceBuffer<uint32_t> keys_, index_, start_, end_;
  DeviceBuffer<Vec3> sorted_x_;
  DeviceBuffer<int32_t> bounds_, coarse_;  ///< the samples' cell box; coarse occupancy per bucket
};

/// Reference for tests: the nearest sample to p among all n (host arrays), within max_range.
NearestSample nearest_sample_brute_force(const Vec3* samples, int64_t n, Vec3 p, float max_range);

namespace cpu {
void hash_grid_keys(const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, uint32_t mask,
                    uint32_t* keys, uint32_t* index, int32_t* bounds, int32_t* coarse);
void hash_grid_ranges(const uint32_t* sorted_keys, const uint32_t* index, const Vec3* x, const Vec3* v, float rewind_dt,
                      int64_t n, uint32_t* start, uint32_t* end, Vec3* sorted_x);
void hash_grid_query(HashGridView g, ParticleView p, float max_range);
}  // namespace cpu
namespace cuda {
void hash_grid_keys(const Vec3* x, const Vec3* v, float rewind_dt, int64_t n, float inv_h, uint32_t mask,
                    uint32_t* keys, uint32_t* index, int32_t* bounds, int32_t* coarse);
void hash_grid_ranges(const uint32_t* sorted_keys, const uint32_t* index, const Vec3* x, const Vec3* v, float rewind_dt,
                      int64_t n, uint32_t* start, uint32_t* end, Vec3* sorted_x);
void hash_grid_query(HashGridView g, ParticleView p, float max_range);
}  // namespace cuda

}  // namespace wb
