// Replays a stroke through the simulator: the StrokePlayer gives the steps (poses,
// sub-steps, pen edges, events), this driver runs them and keeps what a replay reports.
// Session::begin_replay starts the stroke (its ground, the brush, the paint) and drives it, so
// that `wetbrush replay`, `bench`, the studio's time-lapse, Python and the tests take one path.
#pragma once
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/io/stroke_player.h"
#include "core/sim/simulator.h"

namespace wb {

/// The canvas rectangle a replay looks at: the samples' bounding box grown by the brush's
/// reach (length + width), clipped to the canvas.
struct CanvasRect {
  int x0 = 0, y0 = 0, width = 0, height = 0;
};
CanvasRect stroke_region(const Stroke& stroke);

/// One step of a stroke through the simulator, the step driver of `wetbrush replay` and the
/// studio: the palette events due in it, the pen-down reload (`reload`: the pen touches down in
/// this step and the stroke's paint says reload_on_pen_down) with the player's stroke paint, the
/// sub-step poses and Simulator::step. `poses` is the caller's scratch, reused between steps.
void drive_step(Simulator& sim, const StrokePlayer& player, const PlayerStep& step, std::span<const StrokeEvent> events,
                bool reload, std::vector<BrushPose>& poses);

class Replay {
 public:
  /// Drives `player`'s steps through `sim`, whose stroke has begun (Session::begin_replay).
  Replay(Simulator& sim, StrokePlayer& player);

  /// Runs the next player step (all its sub-steps); false when the stroke is over. `before_step`,
  /// when given, is told where the brush will be at the step's end just before it runs (after a
  /// pause passed over: Session's undo records).
  bool advance(const std::function<void(const BrushPose& end)>& before_step = {});
  int64_t steps_done() const { return player_.steps_done(); }
  int64_t step_count() const { return player_.step_count(); }
  double sim_time() const { return last_t_ - player_.t_begin(); }
  const CanvasRect& region() const { return region_; }

  /// Most canvas cells the bristles touched in one step (kept on the device a step at a time;
  /// read here).
  int64_t contact_cells_max() const;
  /// Largest relative segment stretch seen after any step (likewise).
  float max_stretch() const;
  /// Every canvas cell of the region that bristles touched so far (row-major, region-sized).
  std::vector<int32_t> contact_trace() const { return trace_.to_host(); }

  /// Top view of the region: paper, the contact trace, and the bristles of the current
  /// pose drawn over it (darker where closer to the canvas). RGB8, rows top = y0.
  std::vector<uint8_t> brush_image() const;

 private:

  Simulator& sim_;
  StrokePlayer& player_;
  CanvasRect region_;
  DeviceBuffer<int32_t> trace_;
  // Per step, on the device (no host read a step): touched cells and the largest stretch.
  DeviceBuffer<double> contacts_;
  DeviceBuffer<float> stretch_;
  int64_t recorded_ = 0;
  double last_t_ = 0.0;
  std::vector<BrushPose> poses_;  ///< sub-step poses of the current step (reserved once)
};

}  // namespace wb
