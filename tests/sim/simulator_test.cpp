// The whole step of Figure 4 on a small scene: paint books, no paint from a clean brush,
// paint only under a pressed brush, stability under jitter and a very fast stroke.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "core/exec/memory.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {


TEST_F(SimulatorTest, CleanBrushLeavesNoPaint) {
  const SimConfig c = small_config();
  Simulator sim(c, pose_at(c.brush, 128, 128, 0.f, false));
  for (int i = 0; i < 12; ++i) sim.step(pose_at(c.brush, 120.f + i, 128.f, 0.8f), 1.f / 60.f);
  sim.settle();
  EXPECT_EQ(sim.census().total(), 0.0);
  EXPECT_EQ(sim.canvas().total_density(), 0.0);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
}

// The studio's brush preview and swatch read the brush's paint from the device: it is what was
// loaded, it mixes as Algorithm 2 mixes, it runs down as the brush paints, and its bristles hang
// below the ferrule and reach the canvas when pressed.
TEST_F(SimulatorTest, BrushPictureIsTheBrushsPaintAndPose) {
  const SimConfig c = small_config();
  Simulator sim(c, pose_at(c.brush, 128, 128, 0.f, false));
  BrushPicture b = sim.brush_picture();
  EXPECT_EQ(b.amount, 0.f);
  ASSERT_EQ(b.vertices.size(), size_t(c.brush.bristles) * size_t(c.brush.vertices_per_bristle));
  ASSERT_EQ(b.ryb.size(), size_t(c.brush.bristles));
  PaintLoad p = red();
  p.load = 0.6f;
  sim.load_paint(p);
  b = sim.brush_picture();
  EXPECT_NEAR(b.amount, 0.6f, 1e-3f);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.mean_ryb[k], p.ryb[k], 1e-4f);
  for (float f : b.fill) EXPECT_NEAR(f, 0.6f, 1e-3f);
  // Topped up with blue: the mix Algorithm 2 gives, the same as BristleLoad::mean_color.
  PaintLoad blue = p;
  blue.ryb[0] = blue.ryb[1] = 0.f;
  blue.ryb[2] = 1.f;
  blue.load = 0.9f;
  sim.dip(blue);
  b = sim.brush_picture();
  const Vec3 expect = SimulatorTestAccess::load(sim).mean_color(ws_);
  EXPECT_NEAR(b.amount, 0.9f, 1e-3f);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.mean_ryb[k], expect[k], 1e-4f);
  EXPECT_GT(b.mean_ryb[2], 0.2f);
  EXPECT_GT(b.mean_ryb[0], 0.2f);
  // Bristles hang below the ferrule; pressed, their tips reach the canvas; painting uses paint.
  float lowest = 0.f;
  for (const Vec3& v : b.vertices) lowest = std::min(lowest, v.z);
  EXPECT_LT(lowest, -0.5f * c.brush.length);
  for (int i = 0; i < 8; ++i) sim.step(pose_at(c.brush, 120.f + 2.f * i, 128.f, 1.f), 1.f / 60.f);
  b = sim.brush_picture();
  lowest = 0.f;
  for (const Vec3& v : b.vertices) lowest = std::min(lowest, v.z);
  EXPECT_NEAR(lowest, b.canvas_z, 1.5f) << "pressed bristles touch the canvas";
  EXPECT_LT(b.amount, 0.9f) << "painting takes paint off the brush";
  sim.clean();
  EXPECT_EQ(sim.brush_picture().amount, 0.f);
}

// Files, exports and undo see the settled canvas (particles returned by Eq. 16); taking it leaves
// the simulation exactly as it was. A canvas written from outside drops the paint in flight and
// the books record it.
TEST_F(SimulatorTest, SettledCanvasLeavesTheSimulationAsItWasAndReplacedCanvasIsBooked) {
  // On one CPU thread the float atomics add in one order: a simulation that took the copy and one
  // that did not must then go on alike. (On a GPU their order varies: within the spread of such sums.)
  struct OneThread {
    int threads = omp_get_max_threads();
    OneThread() { omp_set_num_threads(1); }
    ~OneThread() { omp_set_num_threads(threads); }
  } one_thread;
  const SimConfig c = small_config();
  Simulator a(c, pose_at(c.brush, 120, 128, 0.f, false)), b(c, pose_at(c.brush, 120, 128, 0.f, false));
  for (Simulator* s : {&a, &b}) s->load_paint(red());
  auto stroke = [&](Simulator& s, int i0, int i1) {
    for (int i = i0; i < i1; ++i) s.step(pose_at(c.brush, 120.f + 2.f * i, 128.f, 0.8f), 1.f / 60.f);
  };
  stroke(a, 0, 8);
  stroke(b, 0, 8);
  ASSERT_GT(a.particle_count(), 0) << "paint in flight";
  const int64_t in_flight = a.particle_count();
  const auto window_before = SimulatorTestAccess::live_window(a)->to_host();
  const ParticleHost particles_before = a.particles().to_host();
  const double canvas_before = a.canvas().total_density();
  const double mass_before = a.census().total();
  const TileStore copy = a.settled_canvas_copy(Device{});
  // Exactly as it was: the window, every particle, the canvas and the books' view of them.
  EXPECT_EQ(SimulatorTestAccess::live_window(a)->to_host(), window_before);
  const ParticleHost particles_after = a.particles().to_host();
  ASSERT_EQ(particles_after.size(), particles_before.size());
  for (size_t k = 0; k < particles_before.size(); ++k) {
    ASSERT_EQ(particles_after.x[k].x, particles_before.x[k].x);
    ASSERT_EQ(particles_after.m[k], particles_before.m[k]);
  }
  // (the canvas's running sum adds and takes back the same paint: equal to rounding)
  EXPECT_NEAR(a.canvas().total_density(), canvas_before, 1e-9 * canvas_before);
  EXPECT_NEAR(a.census().total(), mass_before, 1e-9 * mass_before);
  const PaintCensus census = a.census();
  const double cell_mass = c.params.transfer.cell_mass();
  EXPECT_NEAR(copy.total_density() * cell_mass, census.grid + census.particles, 1e-6 * census.total())
      << "the settled canvas holds the paint on the canvas and in flight";
  EXPECT_EQ(a.particle_count(), in_flight) << "taking it leaves the particles";
  // And it goes on as one that took no copy.
  stroke(a, 8, 12);
  stroke(b, 8, 12);
  const double spread = device_.is_cpu() ? 0.0 : 1e-3;
  EXPECT_NEAR(double(a.particle_count()), double(b.particle_count()), 10.0 * spread * double(b.particle_count()));
  EXPECT_NEAR(a.census().grid, b.census().grid, (spread + 1e-9) * b.census().total());
  EXPECT_NEAR(a.census().bristles, b.census().bristles, (spread + 1e-9) * b.census().total());
  // Undo writes a tile back under the window: the paint in flight goes, and the books say so.
  const PaintCensus before = a.census();
  a.replace_canvas([&](TileStore& canvas) {
    TileData t = canvas.read_tile((128 / kTileSize) * canvas.tiles_x() + 130 / kTileSize);
    std::fill(t.density.begin(), t.density.end(), 0.f);  // as an undo to the blank canvas writes it
    canvas.write_tile(t);
  });
  EXPECT_EQ(a.particle_count(), 0);
  stroke(a, 12, 14);
  EXPECT_LT(std::abs(a.books().max_drift()), 1e-4) << "dropped " << before.particles << " kg in flight";
  EXPECT_EQ(a.counters().nonfinite_events, 0);
}

TEST_F(SimulatorTest, PressedLoadedBrushPaintsUnderItsFootprintAndBooksClose) {
  const SimConfig c = small_config();
  const float cx = 128.f, cy = 128.f;
  Simulator sim(c, pose_at(c.brush, cx, cy, 0.f, false));
  sim.load_paint(red());
  const double loaded = sim.census().total();
  ASSERT_GT(loaded, 0.0);
  for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, cx, cy, 0.25f * float(i)), 1.f / 60.f);
  for (int i = 0; i < 14; ++i) sim.step(pose_at(c.brush, cx, cy, 1.f), 1.f / 60.f);
  for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, cx, cy, 0.f, false), 1.f / 60.f);
  sim.settle();
  // Books: every step closes, and the census equals what was loaded.
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
  EXPECT_NEAR(sim.census().total(), loaded, 1e-4 * loaded);
  EXPECT_LT(sim.books().totals().max_closure_error, 1e-5);
  const double on_canvas = sim.canvas().total_density();
  ASSERT_GT(on_canvas, 0.0) << "a loaded brush pressed into the canvas left no paint";
  // Paint only under the footprint: within the brush's reach of the press point.
  const float reach = 0.5f * c.brush.width + c.brush.length * c.brush.max_press + 4.f;
  double inside = 0.0;
  PaintWindow w(device_, Int3{256, 256, 16});
  SimulatorTestAccess::canvas(sim).gather(w);
  const auto f = w.to_host();
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 256; ++y)
      for (int x = 0; x < 256; ++x) {
        const float d = f[0][(size_t(z) * 256 + y) * 256 + x];
        ASSERT_GE(d, 0.f);
        if (d > 0.f && std::hypot(x + 0.5f - cx, y + 0.5f - cy) <= reach) inside += d;
      }
  EXPECT_GT(inside, 0.99 * on_canvas) << "paint found away from the footprint";
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
}

TEST_F(SimulatorTest, DraggedBrushKeepsPaintingWithWickingAndGridOnlyHoldsNoParticles) {
  // The same drag three ways: wicking (default), without (the paper's model), and grid-only.
  // With wicking the bristles' paint keeps reaching the tips, so more of it is left on the
  // canvas; grid-only paint never stays particles past the step after it was emitted.
  auto drag = [&](float wick, bool particles, int64_t* held_max) {
    SimConfig c = small_config();
    c.params.transfer.wick_rate = wick;
    if (wick == 0.f) c.params.transfer.wick_slide = 0.f;  // the paper's model: no flow along a bristle
    c.particles = particles;
    Simulator sim(c, pose_at(c.brush, 100, 128, 0.f, false));
    sim.load_paint(red());
    int64_t held = 0;
    for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 100.f, 128.f, 0.2f * float(i)), 1.f / 60.f);
    for (int i = 0; i < 24; ++i) {
      sim.step(pose_at(c.brush, 100.f + 2.f * float(i), 128.f, 0.6f), 1.f / 60.f);
      held = std::max(held, sim.particles().size() - sim.books().steps().back().transfer.emitted_count);
    }
    sim.settle();
    EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
    EXPECT_EQ(sim.counters().nonfinite_events, 0);
    if (held_max) *held_max = held;
    return sim.canvas().total_density();
  };
  const double wicked = drag(2000.f, true, nullptr);
  const double paper = drag(0.f, true, nullptr);
  int64_t held = -1;
  const double grid_only = drag(2000.f, false, &held);
  EXPECT_GT(wicked, 1.2 * paper) << "wicking feeds the tips: more paint on the canvas";
  EXPECT_GT(grid_only, 0.0);
  EXPECT_EQ(held, 0) << "grid-only: only this step's emission is held as particles";
}

TEST_F(SimulatorTest, JitterAndVeryFastStrokeStayFiniteAndKeepTheBooks) {
  SimConfig c = small_config();
  Simulator sim(c, pose_at(c.brush, 60, 60, 0.f, false));
  sim.load_paint(red());
  const double loaded = sim.census().total();
  // 50 Hz jitter of +-6 cells while pressed (one step per 1/60 s).
  for (int i = 0; i < 20; ++i) {
    const float j = (i % 2 ? 6.f : -6.f);
    sim.step(pose_at(c.brush, 60.f + j, 60.f - j, 0.7f), 1.f / 60.f);
  }
  // Across the canvas in 0.1 s: 180 cells in 6 steps, sub-stepped as the player would.
  for (int i = 1; i <= 6; ++i) {
    BrushPose poses[8];
    for (int k = 0; k < 8; ++k) poses[k] = pose_at(c.brush, 60.f + 30.f * (i - 1 + (k + 1) / 8.f), 60.f, 0.6f);
    sim.step(poses, 8, 1.f / 60.f);
  }
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
  EXPECT_LE(sim.census().total(), loaded * (1.0 + 1e-4)) << "paint was created";
  const auto pv = sim.particles().to_host();
  for (size_t k = 0; k < pv.size(); ++k) {
    ASSERT_TRUE(std::isfinite(pv.x[k].x) && std::isfinite(pv.x[k].y) && std::isfinite(pv.x[k].z));
    ASSERT_GE(pv.x[k].z, -1e-3f) << "particle below the canvas";
  }
}

/// Painted columns of the canvas: cells (x, y) whose paint column holds at least `min_rho`.
struct Footprint {
  int64_t columns = 0;
  double mass = 0;
  std::vector<float> column;  ///< summed density per (x, y)
};

Footprint footprint_of(Simulator& sim, const Device& device, float min_rho = 0.05f) {
  const CanvasDims d = sim.canvas().dims();
  PaintWindow w(device, Int3{d.width, d.height, d.depth});
  SimulatorTestAccess::canvas(sim).gather(w);
  const auto f = w.to_host();
  Footprint fp;
  fp.column.assign(size_t(d.width) * d.height, 0.f);
  for (int z = 0; z < d.depth; ++z)
    for (size_t c = 0; c < fp.column.size(); ++c) fp.column[c] += f[0][size_t(z) * fp.column.size() + c];
  for (float v : fp.column) {
    fp.columns += v >= min_rho;
    fp.mass += v;
  }
  return fp;
}

TEST_F(SimulatorTest, MorePressureSpreadsAWiderMark) {
  // The mark's width as a painter sees it: the radius of a disc of the area that holds visible
  // paint (more than a tenth of a cell in the column). A firm press splays the bristles, whose
  // tips carry the paint outward. (Where the paint sits inside the mark is not its width: the
  // splaying tips of a round brush lay their paint from the centre outward, docs/TRANSFER.md.)
  auto press = [&](float pressure) {
    const SimConfig c = small_config();
    Simulator sim(c, pose_at(c.brush, 128, 128, 0.f, false));
    sim.load_paint(red());
    for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 128.f, 128.f, pressure * 0.25f * float(i + 1)), 1.f / 60.f);
    for (int i = 0; i < 10; ++i) sim.step(pose_at(c.brush, 128.f, 128.f, pressure), 1.f / 60.f);
    for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, 128.f, 128.f, 0.f, false), 1.f / 60.f);
    sim.settle();
    EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
    const Footprint f = footprint_of(sim, device_);
    EXPECT_GT(f.mass, 0.0) << "pressure " << pressure << " left no mark";
    const int64_t visible = std::count_if(f.column.begin(), f.column.end(), [](float v) { return v > 0.1f; });
    return std::make_pair(std::sqrt(double(visible) / M_PI), f.mass);
  };
  const auto [r_light, m_light] = press(0.25f);
  const auto [r_firm, m_firm] = press(1.f);
  EXPECT_GT(r_firm, 1.15 * r_light) << "visible radius: light " << r_light << ", firm " << r_firm << " cells";
  EXPECT_GT(m_firm, m_light) << "a firm press leaves more paint";
}

TEST_F(SimulatorTest, SecondPassMovesWetPaintAndPicksUpItsColour) {
  // A red stroke along +x; then a clean brush loaded with blue drags across it along +y. The
  // second pass moves red paint (the red columns change) and the blue brush picks red up.
  const SimConfig c = small_config();
  Simulator sim(c, pose_at(c.brush, 100, 128, 0.f, false));
  sim.load_paint(red());
  for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 100.f, 128.f, 0.2f * float(i)), 1.f / 60.f);
  for (int i = 0; i < 28; ++i) sim.step(pose_at(c.brush, 100.f + 2.f * float(i), 128.f, 0.7f), 1.f / 60.f);
  for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, 156.f, 128.f, 0.f, false), 1.f / 60.f);
  sim.settle();
  const Footprint first = footprint_of(sim, device_);
  ASSERT_GT(first.columns, 50);
  sim.clean();
  PaintLoad blue;
  blue.ryb[0] = 0.05f, blue.ryb[1] = 0.05f, blue.ryb[2] = 0.9f;
  blue.load = 0.5f;
  sim.reset_brush(pose_at(c.brush, 128, 100, 0.f, false));
  sim.load_paint(blue);
  const Vec3 before = SimulatorTestAccess::load(sim).mean_color(ws_);
  for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 128.f, 100.f, 0.2f * float(i)), 1.f / 60.f);
  for (int i = 0; i < 28; ++i) sim.step(pose_at(c.brush, 128.f, 100.f + 2.f * float(i), 0.8f), 1.f / 60.f);
  const Vec3 after = SimulatorTestAccess::load(sim).mean_color(ws_);
  for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, 128.f, 156.f, 0.f, false), 1.f / 60.f);
  sim.settle();
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
  EXPECT_GT(after.x, before.x + 0.01f) << "the blue brush took up red: R " << before.x << " -> " << after.x;
  // The red stroke's paint moved: where the two strokes cross its columns changed.
  const Footprint second = footprint_of(sim, device_);
  double moved = 0;
  for (int y = 100; y < 160; ++y)
    for (int x = 100; x < 160; ++x) {
      const size_t id = size_t(y) * 256 + x;
      moved += std::abs(double(second.column[id]) - double(first.column[id]));
    }
  EXPECT_GT(moved, 0.05 * first.mass) << "the second pass left the wet paint where it was";
}

TEST_F(SimulatorTest, StrokeOffTheCanvasEdgeKeepsPaintOnAndAboveTheCanvas) {
  // A stroke that runs off the canvas's right edge: no paint below the canvas or outside it,
  // and nothing is lost (the canvas stores only its own cells; particles stay within it).
  const SimConfig c = small_config();
  Simulator sim(c, pose_at(c.brush, 220, 128, 0.f, false));
  sim.load_paint(red());
  const double loaded = sim.census().total();
  for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 220.f, 128.f, 0.25f * float(i)), 1.f / 60.f);
  for (int i = 0; i < 24; ++i) {
    sim.step(pose_at(c.brush, std::min(220.f + 3.f * float(i), 256.f), 128.f, 0.8f), 1.f / 60.f);
    const auto pv = sim.particles().to_host();
    for (size_t k = 0; k < pv.size(); ++k) {
      ASSERT_GE(pv.x[k].z, 0.f) << "particle below the canvas";
      ASSERT_TRUE(pv.x[k].x >= 0.f && pv.x[k].x <= 256.f && pv.x[k].y >= 0.f && pv.x[k].y <= 256.f)
          << "particle outside the canvas at " << pv.x[k].x << ", " << pv.x[k].y;
    }
  }
  sim.settle();
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
  EXPECT_NEAR(sim.census().total(), loaded, 1e-4 * loaded);
  EXPECT_GT(footprint_of(sim, device_).columns, 0);
}

TEST_F(SimulatorTest, SameStrokeOnCpuAndThisBackend) {
  // The CUDA backend paints what the CPU backend paints. Sums and atomics run in another order,
  // so the two drift apart by rounding: the books close on each, and the canvas's paint and its
  // column heights agree within tolerances that such rounding stays far under.
  if (device_.is_cpu()) GTEST_SKIP() << "run with WB_DEVICE=cuda to compare the CUDA backend with the CPU";
  struct Result {
    double loaded = 0, on_canvas = 0, drift = 0;
    Footprint f;
  };
  auto paint = [&](const Device& d) {
    SimConfig c = small_config();
    c.device = d;
    Simulator sim(c, pose_at(c.brush, 100, 128, 0.f, false));
    sim.load_paint(red());
    Result r;
    r.loaded = sim.census().total();
    for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 100.f, 128.f, 0.2f * float(i)), 1.f / 60.f);
    for (int i = 0; i < 24; ++i) sim.step(pose_at(c.brush, 100.f + 2.f * float(i), 128.f, 0.6f), 1.f / 60.f);
    for (int i = 0; i < 4; ++i) sim.step(pose_at(c.brush, 148.f, 128.f, 0.f, false), 1.f / 60.f);
    sim.settle();
    EXPECT_EQ(sim.counters().nonfinite_events, 0) << d.to_string();
    r.on_canvas = sim.canvas().total_density();
    r.drift = std::abs(sim.books().max_drift());
    r.f = footprint_of(sim, d);
    return r;
  };
  const Result g = paint(device_), h = paint(Device(DeviceType::CPU));
  EXPECT_LT(g.drift, 1e-4);
  EXPECT_LT(h.drift, 1e-4);
  EXPECT_NEAR(g.loaded, h.loaded, 1e-5 * h.loaded);
  ASSERT_GT(h.on_canvas, 0.0);
  EXPECT_NEAR(g.on_canvas, h.on_canvas, 0.01 * h.on_canvas) << "paint left on the canvas";
  double l1 = 0;
  for (size_t i = 0; i < h.f.column.size(); ++i) l1 += std::abs(double(g.f.column[i]) - double(h.f.column[i]));
  std::printf("[          ] canvas paint: %s %.4f, cpu %.4f cells; column L1 %.4f of %.4f; %lld vs %lld columns\n",
              device_.to_string().c_str(), g.on_canvas, h.on_canvas, l1, h.f.mass, (long long)g.f.columns,
              (long long)h.f.columns);
  EXPECT_LT(l1, 0.08 * h.f.mass) << "column heights differ between the backends";
  EXPECT_NEAR(double(g.f.columns), double(h.f.columns), 0.05 * double(h.f.columns));
}

}  // namespace
}  // namespace wb::test
