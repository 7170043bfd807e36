// The small simulator scene the whole-step tests share: a 40-bristle round brush 8 mm long on a
// 256 x 256 x 16 canvas, a 48 x 48 x 16 window, and pen poses along the canvas.
#pragma once
#include "backend_fixture.h"
#include "core/io/pen_pose.h"
#include "core/sim/simulator.h"

namespace wb {
/// The stages' state behind Simulator's API, for tests that poison or inspect it.
struct SimulatorTestAccess {
  // Each may change the state from outside the stages: the next step counts what it receives.
  static Brush& brush(Simulator& s) { return (s.entry_check_ = true, *s.brush_); }
  static Grid& grid(Simulator& s) { return (s.entry_check_ = true, *s.grid_); }
  static ParticleStore& particles(Simulator& s) { return (s.entry_check_ = true, s.particles_); }
  static BristleLoad& load(Simulator& s) { return (s.entry_check_ = true, *s.load_); }
  static TileStore& canvas(Simulator& s) { return (s.entry_check_ = true, s.tiles()); }
  static PaintWindow* live_window(Simulator& s) { return (s.entry_check_ = true, s.live_window()); }
};
}  // namespace wb

namespace wb::test {

class SimulatorTest : public BackendTest {
 protected:
  SimConfig small_config(CanvasDims canvas = CanvasDims{256, 256, 16}) const {
    SimConfig c;
    c.device = device_;
    c.canvas = canvas;
    c.window = Int3{48, 48, 16};
    c.brush = default_brush(BrushShape::Round);
    c.brush.bristles = 40;
    c.brush.length = 40.f;
    c.brush.width = c.brush.thickness = 12.f;
    c.brush.samples_per_bristle = 64;
    c.params.particles.D0 = 12.f;
    c.params.particles.D1 = 6.f;
    return c;
  }
  static BrushPose pose_at(const BrushSpec& b, float x, float y, float pressure, bool down = true) {
    PenSample s;
    s.x = x;
    s.y = y;
    s.pressure = pressure;
    s.down = down;
    return pose_from_pen(s, b);
  }
  static PaintLoad red() {
    PaintLoad p;
    p.ryb[0] = 0.9f, p.ryb[1] = 0.1f, p.ryb[2] = 0.05f;
    p.load = 1.f;
    return p;
  }
};

}  // namespace wb::test
