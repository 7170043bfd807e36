// Paint flows only inside the active window, which follows the brush. Where the brush rests, the
// window slides away from a wall that running paint nears (Simulator::place_window), so a bead
// running down an upright canvas beside a resting brush runs as it would in a taller window,
// instead of stopping on the wall the brush placed (docs/GRID.md "The window's walls").
#include <algorithm>
#include <cstdio>
#include <vector>

#include "core/session/session.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

class WindowFlowTest : public SimulatorTest {
 protected:
  struct Run {
    float front = 0.f;   ///< the lowest row (largest y) holding more than a tenth of a cell of paint
    float centre = 0.f;  ///< the paint's centre of mass down the canvas, y
    double drift = 0.0;  ///< the books' largest drift
    int window_y = 0;    ///< the window's origin, y, at the end
  };

  /// A bead of oily paint 10 x 10 x 8 cells (2 x 2 x 1.6 mm) laid on an upright canvas 12 cells
  /// below a brush held up at rest, left `seconds`; the window `window` cells.
  Run bead_run(Int3 window, float seconds, float oil = 0.9f) {
    SimConfig c = small_config(CanvasDims{128, 256, 16});
    c.window = window;
    c.params.grid.tilt = 90.f;
    const float bx = 64.f, by = 32.f;
    Simulator sim(c, pose_at(c.brush, bx, by, 0.f, false));
    sim.replace_canvas([&](TileStore& canvas) {
      for (int ty = 0; ty < canvas.tiles_y(); ++ty)
        for (int tx = 0; tx < canvas.tiles_x(); ++tx) {
          TileData t = canvas.read_tile(ty * canvas.tiles_x() + tx);
          t.tile_x = tx, t.tile_y = ty;
          const size_t cells = size_t(canvas.tile_cells());
          t.density.resize(cells);
          for (auto* f : {&t.pigment_r, &t.pigment_y, &t.pigment_b, &t.oil, &t.dryness}) f->resize(cells);
          bool any = false;
          for (int z = 0; z < 8; ++z)
            for (int ly = 0; ly < kTileSize; ++ly)
              for (int lx = 0; lx < kTileSize; ++lx) {
                const int x = tx * kTileSize + lx, y = ty * kTileSize + ly;
                if (x < 59 || x >= 69 || y < 44 || y >= 54) continue;
                const size_t at = size_t((z * kTileSize + ly) * kTileSize + lx);
                t.density[at] = 1.f;
                t.pigment_r[at] = encode_unorm16(0.85f), t.pigment_y[at] = encode_unorm16(0.3f);
                t.pigment_b[at] = encode_unorm16(0.05f), t.oil[at] = encode_unorm16(oil);
                t.dryness[at] = 0;
                any = true;
              }
          if (any) canvas.write_tile(t);
        }
    });
    for (int s = 0; s < int(std::lround(seconds * 60.f)); ++s)
      sim.step(pose_at(c.brush, bx, by, 0.f, false), 1.f / 60.f);
    const int window_y = SimulatorTestAccess::grid(sim).window().origin().y;
    const TileStore canvas = sim.settled_canvas_copy(device_);
    const CanvasDims d = canvas.dims();
    std::vector<double> row(size_t(d.height), 0.0);
    for (int id : canvas.allocated_tile_ids()) {
      const TileData t = canvas.read_tile(id);
      for (int z = 0; z < d.depth; ++z)
        for (int ly = 0; ly < kTileSize; ++ly)
          for (int lx = 0; lx < kTileSize; ++lx) {
            const int y = t.tile_y * kTileSize + ly;
            if (y < d.height) row[size_t(y)] += t.density[size_t((z * kTileSize + ly) * kTileSize + lx)];
          }
    }
    Run r;
    double m = 0, my = 0;
    for (int y = 0; y < d.height; ++y) {
      m += row[size_t(y)], my += row[size_t(y)] * (y + 0.5);
      if (row[size_t(y)] > 0.1) r.front = float(y + 1);
    }
    r.centre = float(my / m);
    r.drift = sim.books().max_drift();
    r.window_y = window_y;
    std::printf(
        "[ window %3d x %3d ] oil %.1f: the bead's front at y %.0f, its centre at %.1f after %.1f s, the "
        "window at y %d; books %.1e\n",
        window.x, window.y, oil, r.front, r.centre, seconds, r.window_y, r.drift);
    return r;
  }
};

TEST_F(WindowFlowTest, ABeadBesideARestingBrushRunsAsInAWindowHoldingTheCanvas) {
  // The bead starts at y 44-54; the brush's 128-cell window, centred on it, ends at y 96. Oily
  // paint runs about 70 cells in 0.6 s: in a window holding the whole canvas, its front reaches
  // y 120 (measured) in a window twice as tall (to y 192), where the window centred on the brush
  // stopped it on its wall at 96.
  const Run whole = bead_run(Int3{128, 256, 16}, 0.6f);
  const Run window = bead_run(Int3{128, 128, 16}, 0.6f);
  ASSERT_GT(whole.front, 108.f) << "the scene: the bead runs well past the window's wall at rest";
  EXPECT_NEAR(window.front, whole.front, 2.f);
  EXPECT_NEAR(window.centre, whole.centre, 1.f);
  EXPECT_LT(std::abs(window.drift), 1e-4);
  // Stiff paint holds; nothing flows, and the window stays centred on the brush (y 32 - 64).
  const Run stiff = bead_run(Int3{128, 128, 16}, 0.6f, 0.1f);
  EXPECT_LE(stiff.front, 55.f);
  EXPECT_EQ(stiff.window_y, -32);
}

TEST_F(WindowFlowTest, ABrushLiftedClearLeavesTheWindowToTheRunningPaint) {
  // The brush held up (pen up: its tips 20 cells above the canvas, over the window's top) has
  // nothing in the window to hold it there: a window too small to hold both the brush and the
  // running bead at once follows the bead. Measured: 128 x 96 and 96 x 64 windows both run the
  // bead as the window holding the canvas does (front y 120, centre 107.4); a window held by the
  // brush stopped them on its walls (front y 96 and 64).
  const Run whole = bead_run(Int3{128, 256, 16}, 0.6f);
  for (const Int3 window : {Int3{128, 96, 16}, Int3{96, 64, 16}}) {
    const Run r = bead_run(window, 0.6f);
    EXPECT_NEAR(r.front, whole.front, 2.f) << window.y;
    EXPECT_NEAR(r.centre, whole.centre, 1.f) << window.y;
    EXPECT_GT(r.window_y, 32 + 8 - window.y / 2) << "the window left the brush (y 32)";
    EXPECT_LT(std::abs(r.drift), 1e-4);
  }
}

TEST_F(WindowFlowTest, TheWindowComesBackToTheBrushThatComesDown) {
  // The bead has taken the window away from the lifted brush; the pen then comes down where the
  // brush is, over 0.1 s as the player lowers it: the window is back on the brush before a
  // bristle reaches its top, the stroke paints and the books close.
  SimConfig c = small_config(CanvasDims{128, 256, 16});
  c.window = Int3{96, 64, 16};
  c.params.grid.tilt = 90.f;
  const float bx = 64.f, by = 32.f;
  Simulator sim(c, pose_at(c.brush, bx, by, 0.f, false));
  PaintLoad oily = red();
  oily.oil = 0.9f;
  sim.replace_canvas([&](TileStore& canvas) { put_paint_dab(canvas, 64.f, 50.f, 6.f, 8.f, oily); });
  for (int s = 0; s < 36; ++s) sim.step(pose_at(c.brush, bx, by, 0.f, false), 1.f / 60.f);
  const ActiveWindow& win = SimulatorTestAccess::grid(sim).window();
  ASSERT_GT(win.origin().y, 0) << "the scene: the running paint took the window down the canvas";
  sim.load_paint(red());
  for (int s = 1; s <= 12; ++s) {
    // The elevation from -1 (lifted) to a pressure of 0.5 over 6 steps, then held down.
    const float e = std::min(-1.f + float(s) / 4.f, 0.5f);
    PenSample p;
    p.x = bx, p.y = by, p.pressure = std::max(e, 0.f), p.down = e >= 0.f;
    sim.step(pose_from_pen(p, e, c.brush), 1.f / 60.f);
    const Int3 o = win.origin(), n = win.dims();
    EXPECT_TRUE(by >= float(o.y + 8) && by <= float(o.y + n.y - 8)) << "step " << s << ": the window at y " << o.y;
  }
  // The stroke paints: paint under the brush, where the bead had run away from.
  const TileStore canvas = sim.settled_canvas_copy(device_);
  double under = 0.0;
  for (int id : canvas.allocated_tile_ids()) {
    const TileData t = canvas.read_tile(id);
    for (int z = 0; z < canvas.dims().depth; ++z)
      for (int ly = 0; ly < kTileSize; ++ly)
        for (int lx = 0; lx < kTileSize; ++lx) {
          const int x = t.tile_x * kTileSize + lx, y = t.tile_y * kTileSize + ly;
          if (std::abs(float(x) + 0.5f - bx) < 8.f && std::abs(float(y) + 0.5f - by) < 8.f)
            under += t.density[size_t((z * kTileSize + ly) * kTileSize + lx)];
        }
  }
  std::printf("[ come down ] paint under the brush %.1f cells, books %.1e\n", under, sim.books().max_drift());
  EXPECT_GT(under, 5.0);
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
}

}  // namespace
}  // namespace wb::test
