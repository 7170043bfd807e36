#include "core/grid/active_window.h"

#include <algorithm>
#include <cmath>

#include "core/exec/algorithms.h"
#include "core/exec/memory.h"
#include "core/exec/profile.h"
#include "core/grid/grid.h"

namespace wb {

ActiveWindow::ActiveWindow(TileStore& canvas, Int3 dims, Int3 origin)
    : canvas_(&canvas), paint_(canvas.device(), dims), ws_(canvas.device()), gathered_dev_(canvas.device(), 1) {
  const GridDims d = grid_dims();
  const size_t most = size_t(std::max({d.nu(), d.nv(), d.nw()}));
  for (int c = 0; c < 3; ++c) {
    vel_[c].set_device(device());
    vel_[c].resize(most);  // equal capacities: the shift swaps buffers between components
    vel_[c].resize(size_t(d.faces(c)));
    vel_[c].fill_zero();
  }
  shift_tmp_.set_device(device());
  shift_tmp_.resize(most);
  paint_.set_origin(origin);
  canvas_->gather(paint_);
  sum_gathered();
}

void ActiveWindow::shift_faces(int c, int dx, int dy, int dz) {
  // dst(i, j, k) = src(i + dx, j + dy, k + dz), 0 where that is outside: one offset copy of the
  // lattice (the bandwidth of a copy, no per-element index arithmetic), zero at its two ends
  // (the layers with no source) and at the x and y edges (grid_shift_edges).
  const GridDims d = grid_dims();
  int ex, ey, ez;
  d.face_extent(c, ex, ey, ez);
  const int64_t n = d.faces(c), off = (int64_t(dz) * ey + dy) * ex + dx;
  const int64_t lo = std::clamp<int64_t>(-off, 0, n), hi = std::clamp<int64_t>(n - off, lo, n);
  shift_tmp_.resize(size_t(n));
  float* dst = shift_tmp_.data();
  const float* src = vel_[c].data();
  if (lo > 0) mem::fill_zero(device(), dst, size_t(lo) * sizeof(float));
  if (hi > lo) mem::copy_on_device(device(), dst + lo, src + lo + off, size_t(hi - lo) * sizeof(float));
  if (hi < n) mem::fill_zero(device(), dst + hi, size_t(n - hi) * sizeof(float));
  if (std::abs(dx) < ex && std::abs(dy) < ey && hi > lo)
    grid_shift_edges(device(), dst, ex, ey, ez, dx, dy);
  else if (hi > lo)
    mem::fill_zero(device(), dst, size_t(n) * sizeof(float));  // a move past the window: nothing stays
  vel_[c].swap(shift_tmp_);
}

void ActiveWindow::move_to(Int3 new_origin) {
  const Int3 o = origin();
  if (new_origin == o) return;
  WB_PROFILE_SCOPE("grid.window_move");
  canvas_->scatter(paint_);
  for (int c = 0; c < 3; ++c) shift_faces(c, new_origin.x - o.x, new_origin.y - o.y, new_origin.z - o.z);
  paint_.set_origin(new_origin);
  canvas_->gather(paint_);
  sum_gathered();
}

Int3 ActiveWindow::origin_for(Vec3 brush, int snap) const {
  snap = std::max(snap, 1);
  const Int3 n = dims();
  auto snapped = [&](float centre, int extent) {
    const float start = centre - 0.5f * float(extent);
    return int(std::lround(start / float(snap))) * snap;
  };
  return Int3{snapped(brush.x, n.x), snapped(brush.y, n.y), origin().z};
}

bool ActiveWindow::recentre_on(Vec3 brush, int snap) {
  const Int3 target = origin_for(brush, snap);
  if (target == origin()) return false;
  move_to(target);
  return true;
}

void ActiveWindow::flush() {
  WB_PROFILE_SCOPE("grid.window_flush");
  canvas_->scatter(paint_);
  sum_gathered();
}

void ActiveWindow::restore(const std::vector<std::vector<float>>& host, double gathered_mass) {
  paint_.from_host(host);
  gathered_dev_.copy_from_host(&gathered_mass, 1);
  set_gathered_mass(gathered_mass);
}

void ActiveWindow::sum_gathered() {
  reduce_sum_into(device(), paint_.density.data(), paint_.cell_count(), gathered_dev_.data(), ws_);
  gathered_pending_ = true;
}

double ActiveWindow::gathered_mass() const {
  if (gathered_pending_) {
    double m = 0;
    gathered_dev_.copy_to_host(&m, 1);
    set_gathered_mass(m);
  }
  return gathered_mass_;
}

void ActiveWindow::reload() {
  canvas_->gather(paint_);
  sum_gathered();
}

double ActiveWindow::total_mass(Workspace& ws) const {
  return total_mass_with(paint_.total_density(ws));
}

double ActiveWindow::total_mass_with(double window_density) const {
  return canvas_->total_density() - gathered_mass() + window_density;
}

}  // namespace wb
