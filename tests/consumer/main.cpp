// A consumer of the installed library: a short pressed stroke on a small CPU canvas. Exits 0 when
// the paint census after it is positive and finite.
#include <cmath>
#include <cstdio>
#include <exception>

#include "core/io/pen_pose.h"
#include "core/io/stroke.h"
#include "core/sim/simulator.h"

namespace {
wb::BrushPose pose_at(const wb::BrushSpec& b, float x, float y, float pressure, bool down) {
  wb::PenSample s;
  s.x = x;
  s.y = y;
  s.pressure = pressure;
  s.down = down;
  return wb::pose_from_pen(s, b);
}
}  // namespace

int main() try {
  wb::SimConfig c;
  c.device = wb::Device(wb::DeviceType::CPU);
  c.canvas = wb::CanvasDims{64, 64, 16};
  c.window = wb::Int3{64, 64, 16};
  c.brush = wb::default_brush(wb::BrushShape::Round);
  c.brush.bristles = 40;
  c.brush.length = 40.f;
  c.brush.width = c.brush.thickness = 12.f;
  c.brush.samples_per_bristle = 64;
  c.params.particles.D0 = 12.f;
  c.params.particles.D1 = 6.f;
  wb::Simulator sim(c, pose_at(c.brush, 24.f, 32.f, 0.f, false));
  wb::PaintLoad red;
  red.ryb[0] = 0.9f, red.ryb[1] = 0.1f, red.ryb[2] = 0.05f;
  red.load = 1.f;
  sim.load_paint(red);
  for (int i = 0; i < 8; ++i) sim.step(pose_at(c.brush, 24.f + 2.f * float(i), 32.f, 0.8f, true), 1.f / 60.f);
  sim.settle();
  const double total = sim.census().total();
  std::printf("wetbrush consumer: paint census total %.6g kg, on the canvas %.6g, %lld steps\n", total,
              sim.canvas().total_density(), static_cast<long long>(sim.counters().steps));
  if (!(std::isfinite(total) && total > 0.0)) {
    std::fprintf(stderr, "wetbrush consumer: the census total is not positive and finite\n");
    return 1;
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "wetbrush consumer: %s\n", e.what());
  return 1;
}
