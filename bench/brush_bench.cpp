// One brush step (paper §4.1: dynamics, constraints, minimum density, samples with
// Bishop frames) for 40, 200 and 600 bristles, pressed and dragged along a wavy path,
// on the WB_DEVICE device. Rasterisation into a 128 x 128 x 32 window is timed apart.
#include <math.h>

#include <benchmark/benchmark.h>

#include <cmath>

#include "core/brush/brush.h"
#include "core/exec/device.h"
#include "core/exec/profile.h"

namespace {

wb::BrushPose pose_at(int step, float length) {
  const float t = float(step) / 60.f;
  wb::BrushPose p;
  p.position = wb::Vec3(1000.f + 300.f * t, 1000.f + 60.f * std::sin(5.f * t), length * 0.65f);
  p.rotation = wb::rotation_axis_angle(wb::Vec3(1, 0, 0), 0.35f) * wb::rotation_axis_angle(wb::Vec3(0, 0, 1), 0.3f * t);
  return p;
}

wb::BrushSpec spec_for(int bristles) {
  wb::BrushSpec spec = wb::default_brush(wb::BrushShape::Round);
  spec.bristles = bristles;
  return spec;
}

void BM_BrushStep(benchmark::State& state) {
  const wb::Device d = wb::Device::from_env();
  const wb::BrushSpec spec = spec_for(int(state.range(0)));
  wb::Brush brush(d, spec, pose_at(0, spec.length));
  const wb::BrushEnvironment env;
  int step = 0;
  for (int i = 0; i < 10; ++i) brush.step(pose_at(++step, spec.length), 1.f / 60.f, env);  // pressed, moving
  for (auto _ : state) {
    brush.step(pose_at(++step, spec.length), 1.f / 60.f, env);
    d.synchronize();
  }
  state.counters["vertices"] = double(brush.vertex_count());
  state.counters["samples"] = double(brush.sample_count());
}
BENCHMARK(BM_BrushStep)->Arg(40)->Arg(200)->Arg(600)->Unit(benchmark::kMicrosecond);

void BM_BrushRasterize(benchmark::State& state) {
  const wb::Device d = wb::Device::from_env();
  const wb::BrushSpec spec = spec_for(int(state.range(0)));
  wb::Brush brush(d, spec, pose_at(0, spec.length));
  for (int i = 1; i <= 10; ++i) brush.step(pose_at(i, spec.length), 1.f / 60.f, wb::BrushEnvironment{});
  const wb::Int3 dims{128, 128, 32};
  const size_t cells = size_t(dims.x) * dims.y * dims.z;
  wb::DeviceBuffer<float> psi(d, cells), vx(d, cells), vy(d, cells), vz(d, cells);
  const wb::Vec3 p = brush.pose().position;
  const wb::Int3 origin{int(p.x) - 64, int(p.y) - 64, 0};
  for (auto _ : state) {
    brush.rasterize(origin, dims, psi.data(), vx.data(), vy.data(), vz.data());
    d.synchronize();
  }
}
BENCHMARK(BM_BrushRasterize)->Arg(40)->Arg(200)->Arg(600)->Unit(benchmark::kMicrosecond);

}  // namespace
