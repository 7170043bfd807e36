// Particle stage (paper §4.3, §6) at the paper's Figure 12 load: 210K particles around a
// brush of 200 bristles x 128 samples. Sample-grid build, nearest-sample query, adhesion step
// and rasterisation, on the device named by WB_DEVICE.
#include <benchmark/benchmark.h>

#include <random>

#include "core/exec/device.h"
#include "core/exec/workspace.h"
#include "core/particles/sample_grid.h"
#include "core/particles/particle_store.h"
#include "core/particles/particles.h"
#include "bench_scene.h"
#include "../tests/particles/sample_fixture.h"  // synthetic samples shared with the tests

namespace {
using namespace wb;

struct Scene {
  Device d = Device::from_env();
  Workspace ws{d};
  test::HostSamples hs;
  test::DeviceSamples ds{d};
  ParticleStore store{d};
  SampleGrid grid{d};
  ParticleParams prm;
  test::Region region;  ///< the particles' box grown by the longest range queried (D0)
  float dt = 1.f / 60.f;

  Scene() {
    d.activate();
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    // Round brush, radius 20 cells, bristles 100 cells long, bent back along the stroke (+x
    // motion) as they touch the canvas; 0.8 cells between samples.
    hs.resize(200, 128);
    const Vec3 V(600.f, 0.f, 0.f);
    for (int b = 0; b < 200; ++b) {
      const float r = 20.f * std::sqrt(U(rng)), a = 6.2831853f * U(rng);
      Vec3 p(2000.f + r * std::cos(a), 2000.f + r * std::sin(a), 100.f);
      for (int j = 0; j < 128; ++j) {
        const float s = float(j) / 127.f;
        const Vec3 t = normalize(Vec3(-0.9f * s * s, 0.f, -1.f + 0.9f * s * s));
        const size_t i = size_t(b) * 128 + j;
        hs.x[i] = p;
        hs.t[i] = t;
        hs.n[i] = normalize(cross(Vec3(0, 1, 0), t));
        hs.b[i] = cross(t, hs.n[i]);
        hs.v[i] = V;
        hs.omega[i] = Vec3(0.f, 0.3f, 0.f);
        hs.a[i] = Vec3(-200.f, 0.f, 0.f);
        hs.alpha[i] = Vec3();
        p += t * 0.8f;
      }
    }
    ds.upload(hs);
    // 210K particles around the brush (bench_scene.h).
    ParticleHost ph;
    ph.resize(210000);
    ph.x = bench::positions_around(hs.x, ph.size(), rng);
    for (size_t k = 0; k < ph.size(); ++k) {
      ph.v[k] = Vec3(500.f, 0.f, 0.f);
      ph.m[k] = 1e-9f;
    }
    store.append(ph);
    region = test::region_around(ph.x, prm.D0);
    // In the order the simulator keeps them: by cell (Simulator::particle_stage).
    const Int3 lo(int(std::floor(region.lo.x)), int(std::floor(region.lo.y)), int(std::floor(region.lo.z)));
    store.sort_by_cell(lo, Int3(int(region.hi.x) + 1 - lo.x, int(region.hi.y) + 1 - lo.y, int(region.hi.z) + 1 - lo.z),
                       ws);
  }
};

Scene& scene() {
  static Scene s;
  return s;
}

void BM_SampleGridBuild(benchmark::State& state) {
  Scene& s = scene();
  for (auto _ : state) {
    s.grid.build(s.ds.view(), float(state.range(0)), s.region.lo, s.region.hi, s.ws, s.dt);
    s.d.synchronize();
  }
  state.SetItemsProcessed(state.iterations() * s.ds.view().count());
}
BENCHMARK(BM_SampleGridBuild)->Arg(4)->Unit(benchmark::kMicrosecond);

void BM_NearestSampleQuery(benchmark::State& state) {
  Scene& s = scene();
  s.grid.build(s.ds.view(), float(state.range(0)), s.region.lo, s.region.hi, s.ws, s.dt);
  // 0: D1 (Eq. 10), 1: D0, 2: one cell (the absorption's load spheres, Eq. 14)
  const float range = state.range(1) == 0 ? s.prm.D1 : (state.range(1) == 1 ? s.prm.D0 : 1.f);
  for (auto _ : state) {
    s.grid.query_nearest(s.store.view(), range);
    s.d.synchronize();
  }
  state.SetItemsProcessed(state.iterations() * s.store.size());
}
// cell size (cells) x range (0: D1 = 15, 1: D0 = 50, 2: 1 cell)
BENCHMARK(BM_NearestSampleQuery)
    ->Args({2, 0})
    ->Args({4, 0})
    ->Args({8, 0})
    ->Args({4, 1})
    ->Args({8, 1})
    ->Args({2, 2})
    ->Unit(benchmark::kMillisecond);

void BM_AdhesionStep(benchmark::State& state) {
  Scene& s = scene();
  s.grid.build(s.ds.view(), s.prm.sample_cell, s.region.lo, s.region.hi, s.ws, s.dt);
  s.grid.query_nearest(s.store.view(), s.prm.D0);
  const ParticleHost start = s.store.to_host();
  SolidView solid;
  DeviceBuffer<SampleMotion> motion(s.d, size_t(s.ds.view().count()));
  for (auto _ : state) {
    particles_adhesion_step(s.d, s.store.view(), s.ds.view(), solid, s.prm, s.dt, motion.data());
    s.d.synchronize();
    state.PauseTiming();
    s.store.clear();
    s.store.append(start);  // the same input every iteration
    s.grid.query_nearest(s.store.view(), s.prm.D0);
    s.d.synchronize();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * s.store.size());
}
BENCHMARK(BM_AdhesionStep)->Unit(benchmark::kMillisecond);

void BM_Rasterise(benchmark::State& state) {
  Scene& s = scene();
  // A 128 x 128 x 32 window around the brush.
  const int nx = 128, ny = 128, nz = 32;
  DeviceBuffer<FloatPair> cell(s.d, size_t(nx) * ny * nz), face[3];
  ParticleRasterView g{cell.data(), {}, nx, ny, nz, 1936, 1936, 0};
  for (int c = 0; c < 3; ++c) {
    face[c] = DeviceBuffer<FloatPair>(s.d, size_t(nx + (c == 0)) * (ny + (c == 1)) * (nz + (c == 2)));
    g.face[c] = face[c].data();
  }
  for (auto _ : state) {
    cell.fill_zero();
    for (int c = 0; c < 3; ++c) face[c].fill_zero();
    particles_rasterise(s.d, s.store.view(), g);
    s.d.synchronize();
  }
  state.SetItemsProcessed(state.iterations() * s.store.size());
}
BENCHMARK(BM_Rasterise)->Unit(benchmark::kMillisecond);

}  // namespace
