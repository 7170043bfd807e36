// The host's waits for the device in a step: the CPU backend counts them at the same call sites
// as CUDA, where each drains the stream (mem::host_reads). Each stage has its budget, so that a
// read added to the step fails here, on every machine, not only as a slower step on a GPU.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/exec/memory.h"
#include "core/io/stroke.h"
#include "core/session/session.h"
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
      {"books", 1.0},           // the step's record: sums, census, non-finite counts, rollbacks,
                                // the grid's plan and solve figures, the transfer's scan ends
      {"grid.advect", 0.0},     // none: the paint's reach and layers are planned on the device
      {"grid.viscosity", 0.0},  // none: the device runs the CG until converged (LaunchLoop)
      {"transfer.step", 0.0},   // none: its scan's ends come back with the record
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
  // One wait a step, the lift's included: the step's record.
  const auto& steps = prof.host_reads("sim.step");
  const int64_t most = *std::max_element(steps.begin(), steps.end());
  std::printf("[ waits ] the most in a step: %lld\n", static_cast<long long>(most));
  EXPECT_EQ(most, 1);
  EXPECT_EQ(sim.counters().box_reads, 0) << "with room in the window, its place needs no read";
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
}

// A replay of a hand's strokes: events every 5 ms with the clock's and the hand's jitter, an eased
// landing, a drag, a burst to 300 mm/s and the lift, the pen in the air, and a slow second stroke
// elsewhere. Every step the replay drives waits once: its record.
TEST_F(SimulatorTest, AReplayOfAHandsStrokeWaitsOnceAStep) {
  SimConfig c = small_config();
  c.window = Int3{96, 96, 16};
  Stroke s;
  s.canvas = c.canvas;
  s.brush = c.brush;
  s.paint = red();
  s.source = "a hand's stroke";
  std::mt19937 rng(11);
  std::normal_distribution<float> jitter(0.f, 0.15f), clock(0.f, 0.0004f);
  const auto add = [&](double t, float x, float y, float p, bool down) {
    PenSample q;
    q.t = t + double(clock(rng));
    q.x = x + jitter(rng), q.y = y + jitter(rng);
    q.pressure = down ? std::clamp(p + 0.01f * jitter(rng), 0.f, 1.f) : 0.f;
    q.down = down;
    s.samples.push_back(q);
  };
  // The first stroke: 0.1 s of landing, a drag at 50 mm/s (250 cells/s) bending along y, a
  // burst to 300 mm/s (1500 cells/s) over 60 ms, and the lift.
  double t = 0.0;
  float x = 50.f, y = 110.f;
  for (int i = 0; i <= 20; ++i, t += 0.005) add(t, x, y, 0.8f * float(i) / 20.f, true);
  for (int i = 0; i < 60; ++i, t += 0.005) {
    x += 1.25f;
    y = 110.f + 12.f * std::sin(0.08f * float(i));
    add(t, x, y, 0.8f, true);
  }
  for (int i = 0; i < 12; ++i, t += 0.005) {
    x += 4.f + 0.35f * float(i);
    add(t, x, y, 0.8f - 0.05f * float(i), true);
  }
  // A quarter second in the air (the pen lifts, moves 40 cells, comes down), then the second
  // stroke: a slow drag (5 mm/s).
  const float lx = x, ly = y;
  x = lx - 30.f, y = ly + 25.f;
  for (int i = 1; i < 50; ++i, t += 0.005) add(t, lx + (x - lx) * float(i) / 50.f, ly + (y - ly) * float(i) / 50.f, 0.f, false);
  for (int i = 0; i <= 60; ++i, t += 0.005) add(t, x + 0.125f * float(i), y, std::min(0.7f, 0.05f * float(i)), true);
  std::sort(s.samples.begin(), s.samples.end(), [](const PenSample& a, const PenSample& b) { return a.t < b.t; });

  Session session(c, pose_at(c.brush, 50.f, 110.f, 0.f, false));
  session.begin_replay(s);
  std::vector<int64_t> waits;
  for (;;) {
    const int64_t before = mem::host_reads();
    if (!session.advance()) break;
    waits.push_back(mem::host_reads() - before);
  }
  const Simulator& sim = session.sim();
  ASSERT_GT(waits.size(), 60u);
  const int64_t most = *std::max_element(waits.begin(), waits.end());
  std::printf("[ waits ] a hand's stroke: %zu steps, %.2f waits a step, %lld at most; %lld split steps, %lld box "
              "reads, %lld rests\n",
              waits.size(), mean_of(waits), static_cast<long long>(most),
              static_cast<long long>(sim.counters().split_steps), static_cast<long long>(sim.counters().box_reads),
              static_cast<long long>(sim.counters().rests));
  EXPECT_EQ(most, 1);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  EXPECT_LT(sim.books().max_drift(), 1e-4);
}

}  // namespace
}  // namespace wb::test
