// The simulator: one call of step() is one time step of the paper's Figure 4, with the
// stages called by name in the paper's order. The physics lives in the stage headers;
// this file only sequences them, times them and keeps the books.
#pragma once
#include <memory>

#include "core/brush/brush.h"
#include "core/canvas/tile_store.h"
#include "core/exec/device.h"
#include "core/exec/profile.h"
#include "core/exec/workspace.h"

namespace wb {

struct SimConfig {
  Device device{};
  CanvasDims canvas{};
  BrushSpec brush{};
  BrushSolverParams brush_solver{};
  float dry_threshold = 0.9f;  ///< dryness at and above which paint is solid
};

/// Counters a replay reports (stats JSON) and the studio shows.
struct SimCounters {
  int64_t steps = 0;
  int64_t substeps = 0;
  int64_t nonfinite_events = 0;  ///< steps whose state went non-finite and were contained
};

class Simulator {
 public:
  Simulator(const SimConfig& config, const BrushPose& initial_pose);

  const SimConfig& config() const { return config_; }
  const Device& device() const { return config_.device; }
  TileStore& canvas() { return *canvas_; }
  Brush& brush() { return *brush_; }
  Profiler& profiler() { return profiler_; }
  const SimCounters& counters() const { return counters_; }

  /// One time step of length dt ending at `pose` (Figure 4).
  void step(const BrushPose& pose, float dt);
  /// Puts the brush at rest at `pose` (a new stroke after a lift, or a teleport).
  void reset_brush(const BrushPose& pose);

 private:
  SimConfig config_;
  std::unique_ptr<TileStore> canvas_;
  std::unique_ptr<Brush> brush_;
  Profiler profiler_;
  Workspace ws_;
  SimCounters counters_;
};

}  // namespace wb
