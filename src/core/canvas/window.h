// The active window: a dense block of the canvas (default 128 x 128 x 32 cells)
// gathered from the sparse tiles before the grid stage and scattered back after it
// (DESIGN step 3). Cells outside the canvas are read as empty and never written back.
#pragma once
#include <cstdint>
#include <vector>

#include "core/canvas/paint_fields.h"
#include "core/exec/buffer.h"
#include "core/exec/hd.h"
#include "core/exec/workspace.h"
#include "core/math/vec.h"

namespace wb {

struct Int3 {
  int x = 0, y = 0, z = 0;
  bool operator==(const Int3& o) const { return x == o.x && y == o.y && z == o.z; }
};

/// POD view of the window's paint fields, passed by value to kernels.
struct PaintWindowView {
#define WB_X(name, doc) float* name;
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
  int nx, ny, nz;
  int ox, oy, oz;  ///< canvas cell of the window's (0,0,0)
  WB_HD int64_t index(int x, int y, int z) const { return (int64_t(z) * ny + y) * nx + x; }
  WB_HD int64_t size() const { return int64_t(nx) * ny * nz; }
};

/// Top of the dried paint in window columns c0 .. c0 + lanes - 1 (absolute canvas z), or floor_z
/// where none: the highest cell the grid counts as solid (cell_is_solid), a partly filled one
/// holding its paint at the bottom (the surface is rho up), into top[l]; above[l] receives the
/// first layer over it (0 where none). The columns of a run of parallel_for_runs<kColumnLanes> at once,
/// down every column layer by layer without a branch a cell.
WB_HD WB_INLINE void column_solid_tops(const PaintWindowView& pw, int64_t c0, int lanes, float dry_threshold,
                                       float floor_z, float* top, int* above) {
  const int64_t layer = int64_t(pw.nx) * pw.ny;
  for (int l = 0; l < lanes; ++l) top[l] = floor_z, above[l] = -1;
  for (int k = pw.nz - 1; k >= 0; --k) {
    const int64_t id0 = int64_t(k) * layer + c0;
    for (int l = 0; l < lanes; ++l) {
      const float rho = pw.density[id0 + l];
      const bool found = above[l] < 0 && dried_solid(rho, pw.dryness[id0 + l], dry_threshold);
      top[l] = found ? maxf(floor_z, float(pw.oz + k) + minf(rho, 1.f)) : top[l];
      above[l] = found ? k + 1 : above[l];
    }
  }
  for (int l = 0; l < lanes; ++l) above[l] = above[l] < 0 ? 0 : above[l];
}

class PaintWindow {
 public:
  PaintWindow() = default;
  PaintWindow(const Device& device, Int3 dims);

  const Device& device() const { return device_; }
  Int3 dims() const { return dims_; }
  Int3 origin() const { return origin_; }
  void set_origin(Int3 o) { origin_ = o; }
  int64_t cell_count() const { return int64_t(dims_.x) * dims_.y * dims_.z; }
  PaintWindowView view();
  void fill_zero();

  /// Host copy of every field, in WB_PAINT_FIELDS order, each cell_count() long.
  std::vector<std::vector<float>> to_host() const;
  void from_host(const std::vector<std::vector<float>>& fields);
  /// Sum of density over the window (cells), in double.
  double total_density(Workspace& ws) const;

#define WB_X(name, doc) DeviceBuffer<float> name;
  WB_PAINT_FIELDS(WB_X)
#undef WB_X

 private:
  Device device_;
  Int3 dims_{128, 128, 32};
  Int3 origin_{};
};

}  // namespace wb
