// Memory budgets (docs/RELIABILITY.md "Memory budgets"): a run is estimated from its
// configuration before it allocates, refused at once when the machine or the budget
// (mem::set_budget, --memory-limit) has no room for it, and its particle store grows only into
// what the rest leaves, where the paint stays on the bristles or in the grid and the books close.
#include <chrono>
#include <cstdio>
#include <string>

#include "core/exec/memory.h"
#include "core/sim/memory_plan.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

/// Sets a budget for the test's duration, on the host or the GPUs.
struct BudgetScope {
  BudgetScope(bool cuda, size_t bytes) : cuda(cuda) { mem::set_budget(cuda, bytes); }
  ~BudgetScope() { mem::set_budget(cuda, 0); }
  bool cuda;
};

TEST(MemoryBudget, SizesAreReadInBytesOrWithAUnit) {
  EXPECT_EQ(mem::parse_size("512M"), size_t(512) << 20);
  EXPECT_EQ(mem::parse_size("4G"), size_t(4) << 30);
  EXPECT_EQ(mem::parse_size("4GiB"), size_t(4) << 30);
  EXPECT_EQ(mem::parse_size("1.5g"), size_t(3) << 29);
  EXPECT_EQ(mem::parse_size("2097152"), size_t(2) << 20);
  for (const char* bad : {"", "lots", "4Q", "-1G", "nan", "1K", "4G of it"}) {
    try {
      mem::parse_size(bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("memory size"), std::string::npos) << e.what();
    }
  }
}

TEST(MemoryBudget, AnAllocationPastTheBudgetIsRefusedWithAMessage) {
  const Device cpu{};
  const size_t held = mem::usage(false).in_use;
  BudgetScope scope(false, held + (size_t(2) << 20));
  void* small = mem::allocate(cpu, size_t(1) << 20);
  try {
    mem::allocate(cpu, size_t(4) << 20);
    ADD_FAILURE() << "4 MiB past a 2 MiB budget was allocated";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("memory budget"), std::string::npos) << e.what();
  }
  EXPECT_EQ(mem::usage(false).in_use, held + (size_t(1) << 20)) << "the refused allocation is not booked";
  mem::release(cpu, small);
  EXPECT_LE(mem::room(cpu), size_t(2) << 20);
}

TEST_F(SimulatorTest, AWindowTooLargeForTheBudgetIsRefusedBeforeItAllocates) {
  SimConfig c = small_config(CanvasDims{2048, 2048, 64});
  c.window = Int3{1024, 1024, 64};
  const bool cuda = !device_.is_cpu();
  const size_t held = mem::usage(cuda).in_use;
  BudgetScope scope(cuda, held + (size_t(256) << 20));
  const auto t0 = std::chrono::steady_clock::now();
  try {
    Simulator sim(c, pose_at(c.brush, 90, 128, 0.f, false));
    ADD_FAILURE() << "a 1024 x 1024 x 64 window ran in a 256 MiB budget";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("1024 x 1024 x 64 cells"), std::string::npos) << m;
    EXPECT_NE(m.find("GiB"), std::string::npos) << m;
    EXPECT_NE(m.find("--memory-limit"), std::string::npos) << m;
    EXPECT_NE(m.find("smaller window"), std::string::npos) << m;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_EQ(mem::usage(cuda).in_use, held) << "nothing is allocated";
}

TEST_F(SimulatorTest, TheEstimateCoversWhatAStrokeHolds) {
  // Each window, brush and paint mode: the peak a pressed stroke holds (the ledger's) stays
  // within the estimate, and the estimate is not far above it (the window's term dominates at
  // 128 x 128 x 32).
  struct Case {
    Int3 window;
    int bristles;
    bool particles;
    double most_over;  // largest estimate / peak accepted
  };
  for (const Case& k : {Case{{48, 48, 16}, 40, true, 2.0}, Case{{96, 48, 16}, 40, true, 2.0},
                        Case{{48, 48, 16}, 400, true, 2.0}, Case{{48, 48, 16}, 40, false, 2.0},
                        Case{{128, 128, 32}, 40, true, 1.3}}) {
    SCOPED_TRACE(testing::Message() << k.window.x << " x " << k.window.y << " x " << k.window.z << ", "
                                    << k.bristles << " bristles, particles " << k.particles);
    SimConfig c = small_config(CanvasDims{512, 512, 32});
    c.window = k.window;
    c.brush.bristles = k.bristles;
    c.particles = k.particles;
    const MemoryPlan plan = plan_memory(c);
    const bool cuda = !device_.is_cpu();
    const size_t held = mem::usage(cuda).in_use;
    mem::reset_peak();
    int64_t capacity = 0;
    {
      Simulator sim(c, pose_at(c.brush, 120, 128, 0.f, false));
      sim.load_paint(red());
      for (int i = 0; i < 16; ++i) sim.step(pose_at(c.brush, 120.f + 3.f * float(i), 128.f, 0.8f), 1.f / 60.f);
      capacity = SimulatorTestAccess::particles(sim).capacity();
      // The whole canvas rendered, as a replay's picture and a save's are.
      sim.settle();
      Renderer renderer(device_);
      const Image picture = renderer.render(SimulatorTestAccess::canvas(sim), Camera::top(c.canvas));
      EXPECT_EQ(picture.width, c.canvas.width);
    }
    const double peak = double(mem::usage(cuda).peak - held);
    const double estimate = double(plan.base() + capacity * plan.per_particle);
    std::printf("[ memory ] %d x %d x %d, %d bristles, particles %d: peak %s, estimate %s (window %s, brush %s, "
                "canvas %s, picture %s, %lld particles' capacity %s)\n",
                k.window.x, k.window.y, k.window.z, k.bristles, int(k.particles), mem::format_bytes(peak).c_str(),
                mem::format_bytes(estimate).c_str(), mem::format_bytes(double(plan.window)).c_str(),
                mem::format_bytes(double(plan.brush)).c_str(), mem::format_bytes(double(plan.canvas)).c_str(),
                mem::format_bytes(double(plan.picture)).c_str(), static_cast<long long>(capacity), mem::format_bytes(double(capacity * plan.per_particle)).c_str());
    EXPECT_GE(estimate, peak) << "estimate " << mem::format_bytes(estimate) << ", peak " << mem::format_bytes(peak);
    EXPECT_LE(estimate, k.most_over * peak) << "estimate " << mem::format_bytes(estimate) << ", peak "
                                            << mem::format_bytes(peak);
  }
}

TEST_F(SimulatorTest, AtTheBudgetsParticleLimitThePaintStaysAndTheBooksClose) {
  // A budget that leaves room for 2000 particles past the run's estimate: the store stops there,
  // the particles not made are counted, no allocation fails and the paint's books close.
  SimConfig c = small_config();
  const MemoryPlan plan = plan_memory(c);
  const int64_t room_for = 2000;
  const bool cuda = !device_.is_cpu();
  BudgetScope scope(cuda, mem::usage(cuda).in_use + size_t(plan.base() + room_for * plan.per_particle));
  Simulator sim(c, pose_at(c.brush, 90, 128, 0.f, false));
  EXPECT_EQ(sim.particle_limit(), room_for);
  sim.load_paint(red());
  for (int i = 0; i < 40; ++i) sim.step(pose_at(c.brush, 90.f + 1.5f * float(i), 128.f, 0.9f), 1.f / 60.f);
  for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, 150.f, 128.f, 0.f, false), 1.f / 60.f);
  EXPECT_LE(sim.counters().particles_max, room_for);
  EXPECT_GT(sim.counters().particles_refused, 0) << "the stroke wants more particles than the budget's";
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
}

}  // namespace
}  // namespace wb::test
