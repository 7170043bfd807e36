#include "core/sim/simulator.h"

namespace wb {

Simulator::Simulator(const SimConfig& config, const BrushPose& initial_pose)
    : config_(config), profiler_(config.device), ws_(config.device) {
  config_.device.activate();
  canvas_ = std::make_unique<TileStore>(config_.device, config_.canvas);
  brush_ = std::make_unique<Brush>(config_.device, config_.brush, initial_pose, config_.brush_solver);
}

void Simulator::reset_brush(const BrushPose& pose) { brush_->reset(pose); }

void Simulator::step(const BrushPose& pose, float dt) {
  ProfilerGuard guard(&profiler_);
  WB_PROFILE_SCOPE("sim.step");
  const int64_t rollbacks_before = brush_->stats().nonfinite;

  // --- 1-2. Brush (§4.1): Eq. 2 in the brush frame, PBD constraints, collisions,
  //          minimum density; then Hermite samples with Bishop frames. ----------------
  BrushEnvironment env;
  env.solid.tiles = canvas_->view();
  env.solid.dryness_threshold = config_.dry_threshold;
  env.solid.valid = canvas_->allocated_tiles() > 0;  // an empty canvas has no dried paint
  brush_->step(pose, dt, env);

  ++counters_.steps;
  counters_.nonfinite_events += brush_->stats().nonfinite - rollbacks_before;
}

}  // namespace wb
