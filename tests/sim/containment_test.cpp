// Non-finite containment, proven stage by stage: a NaN or an infinity put into one part of the
// live state (the window's paint and velocity, the particles, the brush's load, the bristle
// samples) is found within the step, counted, and removed before anything renders, scatters or
// saves it; the painting saved afterwards holds only finite values.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/exec/memory.h"
#include "core/io/document.h"
#include "core/render/renderer.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

bool all_finite(const std::vector<float>& v) {
  for (float x : v)
    if (!std::isfinite(x)) return false;
  return true;
}
bool all_finite(const std::vector<Vec3>& v) {
  for (const Vec3& x : v)
    if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) return false;
  return true;
}

/// Writes `value` into elements 0, n/3 and 2n/3 of a device array of n floats.
void poison(const Device& d, float* p, int64_t n, float value) {
  if (n <= 0) return;
  for (int64_t i : {int64_t(0), n / 3, 2 * n / 3}) mem::copy_from_host(d, p + i, &value, sizeof(float));
}

class ContainmentTest : public SimulatorTest {
 protected:
  /// What a failure names: the first part of the live state holding a non-finite value.
  static std::string nonfinite_part(Simulator& sim) {
    ActiveWindow& win = SimulatorTestAccess::grid(sim).window();
    const auto fields = win.paint().to_host();
    for (size_t f = 0; f < fields.size(); ++f)
      if (!all_finite(fields[f])) return "window field " + std::to_string(f);
    for (int c = 0; c < 3; ++c)
      if (!all_finite(win.velocity(c).to_host())) return "window velocity " + std::to_string(c);
    const ParticleHost p = sim.particles().to_host();
    if (!all_finite(p.x) || !all_finite(p.v)) return "particle position or velocity";
    for (const std::vector<float>* f : {&p.m, &p.pigment_r, &p.pigment_y, &p.pigment_b, &p.oil, &p.dryness})
      if (!all_finite(*f)) return "particle paint";
    const BristleLoadHost l = sim.load().to_host();
    for (const std::vector<float>* f : {&l.m, &l.pigment_r, &l.pigment_y, &l.pigment_b, &l.oil})
      if (!all_finite(*f)) return "brush load";
    if (!all_finite(sim.brush().samples_to_host())) return "bristle samples";
    if (!all_finite(sim.brush().vertices_to_host())) return "bristle vertices";
    return "";
  }
};

TEST_F(ContainmentTest, PoisonInAnyStageIsFoundCountedAndNeverSaved) {
  struct Target {
    const char* name;
    std::function<void(Simulator&, const Device&)> inject;
    bool derived = false;  ///< recomputed at the start of the next step: nothing reads it first
  };
  const std::vector<Target> targets = {
      {"window density", [](Simulator& s, const Device& d) {
         PaintWindow& w = SimulatorTestAccess::grid(s).window().paint();
         poison(d, w.density.data(), w.cell_count(), kNaN);
       }},
      {"window pigment", [](Simulator& s, const Device& d) {
         PaintWindow& w = SimulatorTestAccess::grid(s).window().paint();
         poison(d, w.pigment_y.data(), w.cell_count(), kInf);
       }},
      {"window velocity", [](Simulator& s, const Device&) {
         // Every x face: the brush's drag and the advection read them at once.
         DeviceBuffer<float>& u = SimulatorTestAccess::grid(s).window().velocity(0);
         u.copy_from_host(std::vector<float>(u.size(), kNaN));
       }},
      {"particle position", [](Simulator& s, const Device& d) {
         poison(d, reinterpret_cast<float*>(SimulatorTestAccess::particles(s).x.data()), 3 * SimulatorTestAccess::particles(s).size(), kNaN);
       }},
      {"particle velocity", [](Simulator& s, const Device& d) {
         poison(d, reinterpret_cast<float*>(SimulatorTestAccess::particles(s).v.data()), 3 * SimulatorTestAccess::particles(s).size(), kInf);
       }},
      {"particle mass", [](Simulator& s, const Device& d) { poison(d, SimulatorTestAccess::particles(s).m.data(), SimulatorTestAccess::particles(s).size(), kInf); }},
      {"particle pigment", [](Simulator& s, const Device& d) {
         poison(d, SimulatorTestAccess::particles(s).pigment_r.data(), SimulatorTestAccess::particles(s).size(), kNaN);
       }},
      {"load mass", [](Simulator& s, const Device& d) { poison(d, SimulatorTestAccess::load(s).m.data(), SimulatorTestAccess::load(s).size(), kNaN); }},
      {"load pigment", [](Simulator& s, const Device& d) { poison(d, SimulatorTestAccess::load(s).pigment_b.data(), SimulatorTestAccess::load(s).size(), kInf); }},
      {"sample velocity", [](Simulator& s, const Device& d) {
         SampleView v = SimulatorTestAccess::brush(s).samples();
         poison(d, reinterpret_cast<float*>(v.v), 3 * v.count(), kNaN);
       },
       true},
  };
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "wb_containment_test";
  std::filesystem::create_directories(dir);
  for (const Target& t : targets) {
    SCOPED_TRACE(t.name);
    const SimConfig c = small_config();
    Simulator sim(c, pose_at(c.brush, 60, 128, 0.f, false));
    sim.load_paint(red());
    float x = 60.f;
    auto drag = [&](int steps) {
      for (int i = 0; i < steps; ++i, x += 3.f) sim.step(pose_at(c.brush, x, 128.f, 0.6f), 1.f / 60.f);
    };
    drag(8);
    ASSERT_GT(sim.particles().size(), 0) << "the scene must hold particles to poison";
    ASSERT_EQ(sim.counters().nonfinite_events, 0);
    t.inject(sim, device_);
    drag(1);
    if (!t.derived) EXPECT_GE(sim.counters().nonfinite_events, 1) << "not reported";
    EXPECT_EQ(nonfinite_part(sim), "") << "left in the state after the step";
    drag(4);
    for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, x, 128.f, 0.f, false), 1.f / 60.f);
    sim.settle();
    EXPECT_EQ(nonfinite_part(sim), "");
    EXPECT_TRUE(std::isfinite(sim.census().total())) << "the books";
    // The painting saved now reads back finite, every field of every cell.
    const std::string path = (dir / "painting.ora").string();
    const Image merged(1, 1);
    save_painting(path, sim.canvas(), merged, nlohmann::json::object());
    Painting back = load_painting(path, device_);
    const CanvasDims d = back.canvas.dims();
    PaintWindow w(device_, Int3{d.width, d.height, d.depth});
    back.canvas.gather(w);
    const auto fields = w.to_host();
    for (size_t f = 0; f < fields.size(); ++f) EXPECT_TRUE(all_finite(fields[f])) << "saved field " << f;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace wb::test
