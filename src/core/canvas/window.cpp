#include "core/canvas/window.h"

#include <cstdint>

#include "core/exec/algorithms.h"

namespace wb {

PaintWindow::PaintWindow(const Device& device, Int3 dims) : device_(device), dims_(dims) {
  WB_REQUIRE(dims.x > 0 && dims.y > 0 && dims.z > 0 && dims.x <= 4096 && dims.y <= 4096 && dims.z <= 1024,
             "window dimensions out of range");
  // The grid's kernels index cells and faces in 32 bits (GridDims::split).
  WB_REQUIRE(int64_t(dims.x + 1) * (dims.y + 1) * (dims.z + 1) <= int64_t(UINT32_MAX),
             "window of more than 2^32 cells");
#define WB_X(name, doc) \
  name.set_device(device); \
  name.resize(size_t(cell_count()));
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
  fill_zero();
}

PaintWindowView PaintWindow::view() {
  PaintWindowView v{};
#define WB_X(name, doc) v.name = name.data();
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
  v.nx = dims_.x;
  v.ny = dims_.y;
  v.nz = dims_.z;
  v.ox = origin_.x;
  v.oy = origin_.y;
  v.oz = origin_.z;
  return v;
}

void PaintWindow::fill_zero() {
#define WB_X(name, doc) name.fill_zero();
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
}

std::vector<std::vector<float>> PaintWindow::to_host() const {
  std::vector<std::vector<float>> out;
#define WB_X(name, doc) out.push_back(name.to_host());
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
  return out;
}

void PaintWindow::from_host(const std::vector<std::vector<float>>& fields) {
  WB_REQUIRE(fields.size() == size_t(kPaintFieldCount), "PaintWindow::from_host: wrong field count");
  int i = 0;
#define WB_X(name, doc)                                                                              \
  WB_REQUIRE(fields[i].size() == size_t(cell_count()), "PaintWindow::from_host: wrong field size"); \
  name.copy_from_host(fields[i++]);
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
}

double PaintWindow::total_density(Workspace& ws) const {
  return reduce_sum(device_, density.data(), cell_count(), ws);
}

}  // namespace wb
