// Sample grid: validation and the one runtime dispatch of its drivers (sample_grid_impl.h).
#include "core/particles/sample_grid.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "core/exec/algorithms.h"

namespace wb {
WB_DEFINE_DISPATCHERS(WB_SAMPLE_GRID_KERNELS)

namespace {

/// The grid's cell table holds at most this many cells (128 M, 512 MiB). The simulator's region
/// (its window's columns over the canvas's depth, up to 1024 cells) stays below it at the default
/// 2-cell grid for windows up to about 980 x 980 columns (a 128 x 128 window over 64 cells: 0.3 M);
/// a larger one is refused with the region's size.
constexpr int64_t kMaxCells = int64_t(1) << 27;
}  // namespace

SampleGrid::SampleGrid(const Device& device) : device_(device) {
  keys_.set_device(device);
  index_.set_device(device);
  first_.set_device(device);
  occupied_.set_device(device);
  near_.set_device(device);
  sorted_x_.set_device(device);
  box_.set_device(device);
  box_.resize(6);
}

void SampleGrid::build(const SampleView& s, float cell_size, Vec3 region_lo, Vec3 region_hi, Workspace& ws,
                       float rewind_dt) {
  WB_REQUIRE(std::isfinite(cell_size) && cell_size > 0.f,
             "SampleGrid::build: cell size must be positive, got " + std::to_string(cell_size));
  WB_REQUIRE(s.bristles >= 0 && s.per_bristle >= 0, "SampleGrid::build: negative sample counts");
  const int64_t n = s.count();
  WB_REQUIRE(n < (int64_t(1) << 31), "SampleGrid::build: too many samples (" + std::to_string(n) + ")");
  WB_REQUIRE(n == 0 || s.x != nullptr, "SampleGrid::build: sample positions are null");
  WB_REQUIRE(std::isfinite(rewind_dt) && rewind_dt >= 0.f, "SampleGrid::build: rewind time must be >= 0");
  WB_REQUIRE(rewind_dt == 0.f || n == 0 || s.v != nullptr, "SampleGrid::build: rewinding needs sample velocities");
  WB_REQUIRE(isfinite3(region_lo) && isfinite3(region_hi), "SampleGrid::build: the region is not finite");
  count_ = n;
  h_ = cell_size;
  const float inv_h = 1.f / h_;
  CellBox region;
  int lo[3], hi[3];
  sample_cell_of(region_lo, inv_h, lo[0], lo[1], lo[2]);
  sample_cell_of(region_hi, inv_h, hi[0], hi[1], hi[2]);
  int64_t n_axis[3];
  double volume = 1.0;
  for (int a = 0; a < 3; ++a) {
    WB_REQUIRE(lo[a] <= hi[a], "SampleGrid::build: the region is empty");
    region.lo[a] = lo[a];
    region.hi[a] = hi[a];
    n_axis[a] = int64_t(hi[a]) - lo[a] + 1;
    volume *= double(n_axis[a]);
  }
  WB_REQUIRE(volume <= double(kMaxCells),
             "SampleGrid::build: the region is " + std::to_string(n_axis[0]) + " x " + std::to_string(n_axis[1]) +
                 " x " + std::to_string(n_axis[2]) + " cells of " + std::to_string(cell_size) + ", more than " +
                 std::to_string(kMaxCells));
  const int64_t cells = n_axis[0] * n_axis[1] * n_axis[2];
  const int64_t coarse_cells = int64_t(coarse_count(n_axis[0])) * coarse_count(n_axis[1]) * coarse_count(n_axis[2]);
  capacity_ = cells;
  coarse_capacity_ = coarse_cells;
  if (first_.size() < size_t(cells) + 1) first_.grow_keep(size_t(cells) + 1);
  if (occupied_.size() < size_t(coarse_cells)) {
    occupied_.grow_keep(size_t(coarse_cells));
    near_.grow_keep(size_t(coarse_cells));
  }
  if (keys_.size() < size_t(n)) {
    keys_.grow_keep(size_t(n));
    index_.grow_keep(size_t(n));
    sorted_x_.grow_keep(size_t(n));
  }
  sample_grid_box(device_, s.x, s.v, rewind_dt, n, inv_h, region, box_.data());
  sample_grid_keys(device_, s.x, s.v, rewind_dt, n, inv_h, region, box_.data(), keys_.data(), index_.data());
  int bits = 1;  // keys run to the box's cells, at most the region's
  while ((int64_t(1) << bits) <= cells) ++bits;
  if (n > 0) sort_by_key(device_, keys_.data(), index_.data(), n, bits, ws);
  sample_grid_first(device_, keys_.data(), index_.data(), s.x, s.v, rewind_dt, n, box_.data(), first_.data(),
                    sorted_x_.data());
  sample_grid_coarse(device_, box_.data(), first_.data(), coarse_capacity_, occupied_.data());
}

SampleGridView SampleGrid::view() const {
  return SampleGridView{first_.data(), index_.data(), sorted_x_.data(), count_, h_, box_.data(), near_.data()};
}

void SampleGrid::query_nearest(const ParticleView& p, float max_range) {
  WB_REQUIRE(std::isfinite(max_range) && max_range > 0.f,
             "SampleGrid::query_nearest: range must be positive, got " + std::to_string(max_range));
  WB_REQUIRE(first_.size() > 0, "SampleGrid::query_nearest: build() was not called");
  WB_REQUIRE(p.count >= 0, "SampleGrid::query_nearest: negative particle count");
  // A sample within max_range of a point lies at most F = ceil(max_range / h) cells from the
  // point's along each axis (floor(a + d) - floor(a) <= ceil(d); a hundredth of a cell more for
  // the rounding of x / h on a large canvas), so at most ceil(F / kCoarse) coarse cells.
  const int fine = int(std::ceil(max_range / h_ + 0.01f));
  const int reach = (fine + kCoarse - 1) / kCoarse;
  sample_grid_near(device_, box_.data(), occupied_.data(), reach, coarse_capacity_, near_.data());
  sample_grid_query(device_, view(), p, max_range);
}

NearestSample nearest_sample_brute_force(const Vec3* samples, int64_t n, Vec3 p, float max_range) {
  float best_d2 = max_range * max_range;
  int32_t best = -1;
  for (int64_t i = 0; i < n; ++i) {
    const float d2 = length2(samples[i] - p);
    if (d2 < best_d2) {  // strict: the lowest index wins ties, as in the grid query
      best_d2 = d2;
      best = int32_t(i);
    }
  }
  return best >= 0 ? NearestSample{best, std::sqrt(best_d2)} : NearestSample{-1, max_range};
}

}  // namespace wb
