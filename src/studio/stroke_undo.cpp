#include "studio/stroke_undo.h"

#include <algorithm>

namespace wb::studio {

void StrokeUndo::before_step(Simulator& sim, const PenSample& a, const PenSample& b) {
  // Cells around the pen that one step may change: the active window, centred near the brush's
  // footprint (the bristles' reach) and snapped to the grid's window snap.
  const SimConfig& c = sim.config();
  const int reach = int(c.brush.length + std::max(c.brush.width, c.brush.thickness)) +
                    std::max(c.window.x, c.window.y) / 2 + c.params.grid.window_snap + 2;
  const int x0 = int(std::min(a.x, b.x)) - reach, x1 = int(std::max(a.x, b.x)) + reach;
  const int y0 = int(std::min(a.y, b.y)) - reach, y1 = int(std::max(a.y, b.y)) + reach;
  open_ = true;
  rec_.capture_rect(sim.canvas(), x0, y0, x1, y1);
}

std::shared_ptr<TileDiff> StrokeUndo::finish(Simulator& sim) {
  if (!open_) return nullptr;
  open_ = false;
  auto diff = std::make_shared<TileDiff>();
  const Int3 o = sim.live_window()->origin(), n = sim.live_window()->dims();
  sim.with_settled_canvas([&](TileStore& c) {
    *diff = rec_.finish(c);
    rec_.capture_rect(c, o.x, o.y, o.x + n.x, o.y + n.y);
  });
  return diff->empty() ? nullptr : diff;
}

}  // namespace wb::studio
