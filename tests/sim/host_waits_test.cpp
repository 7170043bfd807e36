// The host's waits for the device in a step: the CPU backend counts them at the same call sites
// as CUDA, where each drains the stream (mem::host_reads). Each stage has its budget, so that a
// read added to the step fails here, on every machine, not only as a slower step on a GPU.
#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/exec/memory.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

double mean_of(const std::vector<int64_t>& v) {
  double s = 0.0;
  for (int64_t x : v) s += double(x);
  return v.empty() ? 0.0 : s / double(v.size());
}

TEST_F(SimulatorTest, HostWaitsPerStepStayWithinEachStagesBudget) {
  SimConfig c = small_config();
  c.window = Int3{96, 96, 16};  // room around the brush: the window is placed without a read
  Simulator sim(c, pose_at(c.brush, 90, 128, 0.f, false));
  sim.load_paint(red());
  const float dt = 1.f / 60.f;
  for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 90.f, 128.f, 0.25f * float(i)), dt);
  // A pressed stroke across the canvas (the window follows it), in sub-steps, then held still.
  for (int i = 0; i < 24; ++i) {
    BrushPose poses[4];
    for (int s = 0; s < 4; ++s) poses[s] = pose_at(c.brush, 90.f + 3.f * float(i) + 0.75f * float(s + 1), 128.f, 0.8f);
    sim.step(poses, 4, dt);
  }
  for (int i = 0; i < 8; ++i) sim.step(pose_at(c.brush, 162.f, 128.f, 0.8f), dt);
  for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, 162.f, 128.f, 0.f, false), dt);  // the lift
  const Profiler& prof = sim.profiler();
  ASSERT_EQ(prof.host_reads("sim.step").size(), 42u);
  ASSERT_GT(prof.count("grid.window_move"), 4u) << "the stroke moves the window";
  // Reads a step, the mean over the stroke, by scope: what each may make and why.
  const std::map<std::string, double> budget = {
      {"brush.step", 0.0},      // sub-steps roll back on the device; the record reports it
      {"books", 1.0},           // the step's record: sums, census, non-finite counts, rollbacks
      {"grid.advect", 0.0},     // none: the paint's reach and layers are planned on the device
      {"grid.viscosity", 1.2},  // CG's one test when the plan holds (the fluid faces' count with
                                // it); a solve past its plan, as at the lift, one more
      {"transfer.step", 1.0},   // one scan's ends: the survivors, the emission, Eq. 15's candidates
      {"window", 0.0},          // none: the samples' box comes with the last step's record, the
                                // tiles are allocated on the device, the particles a move returns
                                // are compacted with the transfer's
  };
  for (const auto& [scope, most] : budget) {
    const double m = mean_of(prof.host_reads(scope));
    std::printf("[ waits ] %-16s %.2f a step (budget %.1f)\n", scope.c_str(), m, most);
    EXPECT_LE(m, most) << scope;
  }
  std::printf("[ waits ] the window placed on the box read back on %lld of %lld steps; %zu moves\n",
              static_cast<long long>(sim.counters().box_reads), static_cast<long long>(sim.counters().steps),
              prof.count("grid.window_move"));
  const double total = mean_of(prof.host_reads("sim.step"));
  std::printf("[ waits ] %-16s %.2f a step; %.0f launches a step\n", "sim.step", total,
              mean_of(prof.launches("sim.step")));
  EXPECT_LE(total, 3.2) << "a step's host waits";
  // The worst step: the lift, where Eq. 9 lifts the paint the tips hold and the viscous solve
  // runs past its plan (a read more).
  const auto& steps = prof.host_reads("sim.step");
  const int64_t most = *std::max_element(steps.begin(), steps.end());
  std::printf("[ waits ] the most in a step: %lld\n", static_cast<long long>(most));
  EXPECT_LE(most, 5);
  EXPECT_EQ(sim.counters().box_reads, 0) << "with room in the window, its place needs no read";
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
}

}  // namespace
}  // namespace wb::test
