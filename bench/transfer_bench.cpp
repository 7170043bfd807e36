// Transfer stage (paper §5, Eq. 12-16) at the paper's Figure 12 load: a loaded round brush of
// 200 bristles x 128 samples pressed on a 128 x 128 x 32 window holding a stripe of paint,
// with 210K particles around it. Each stage, and a whole step, from the same state every
// iteration, on the device named by WB_DEVICE.
#include <benchmark/benchmark.h>

#include <random>

#include "core/canvas/window.h"
#include "core/exec/device.h"
#include "core/exec/workspace.h"
#include "core/particles/sample_grid.h"
#include "core/particles/particle_store.h"
#include "core/transfer/bristle_load.h"
#include "core/transfer/transfer.h"
#include "bench_scene.h"
#include "../tests/particles/sample_fixture.h"  // synthetic samples shared with the tests

namespace {
using namespace wb;

struct TransferScene {
  Device d = Device::from_env();
  Workspace ws{d};
  test::HostSamples hs;
  test::DeviceSamples ds{d};
  ParticleStore store{d};
  ParticleHost particles0;
  SampleGrid grid{d};
  PaintWindow window{d, Int3{128, 128, 32}};
  std::vector<std::vector<float>> paint0;
  BristleLoad load;
  BristleLoadHost load0;
  Transfer transfer{d};
  TransferEnv env;

  TransferScene() {
    d.activate();
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    // Round brush, radius 20 cells, bristles 100 cells long, bent back along the stroke (+x) as
    // they touch the canvas at z ~ 1; 0.8 cells between samples.
    hs.resize(200, 128);
    for (int b = 0; b < 200; ++b) {
      const float r = 20.f * std::sqrt(U(rng)), a = 6.2831853f * U(rng);
      Vec3 p(2000.f + r * std::cos(a), 2000.f + r * std::sin(a), 1.f);  // tip
      for (int j = 0; j < 128; ++j) {
        const float s = 1.f - float(j) / 127.f;  // 0 at the root
        const Vec3 t = normalize(Vec3(0.9f * s * s, 0.f, 1.f - 0.9f * s * s));
        const size_t i = size_t(b) * 128 + j;
        hs.x[i] = p;
        hs.t[i] = t;
        hs.n[i] = normalize(cross(Vec3(0, 1, 0), t));
        hs.b[i] = cross(t, hs.n[i]);
        hs.v[i] = Vec3(600.f, 0.f, 0.f);
        p += t * 0.8f;
      }
    }
    ds.upload(hs);
    // Window centred on the brush; a stripe of paint 128 x 30 cells, 2 cells thick, across it.
    window.set_origin(Int3{1936, 1936, 0});
    paint0.assign(kPaintFieldCount, std::vector<float>(size_t(window.cell_count()), 0.f));
    for (int k = 0; k < 2; ++k)
      for (int j = 49; j < 79; ++j)
        for (int i = 0; i < 128; ++i) {
          const size_t c = (size_t(k) * 128 + j) * 128 + i;
          paint0[0][c] = 0.9f;
          paint0[2][c] = 1.f;  // yellow
          paint0[4][c] = 0.3f;
        }
    window.from_host(paint0);
    // 210K particles around the brush (bench_scene.h); every tenth, the far ones, at rest.
    particles0.resize(210000);
    particles0.x = bench::positions_around(hs.x, particles0.size(), rng);
    for (size_t k = 0; k < particles0.size(); ++k) {
      particles0.v[k] = k % 10 == 0 ? Vec3(0.f, 0.f, 0.f) : Vec3(500.f, 0.f, 0.f);
      particles0.m[k] = 3e-10f;
      particles0.pigment_r[k] = 1.f;
      particles0.oil[k] = 0.3f;
    }
    load = BristleLoad(d, ds.view().count());
    PaintLoad paint;
    load.fill(paint);
    load0 = load.to_host();
    env.paint = window.view();
    env.D0 = 50.f;
    reset();
  }

  /// The same starting state for every iteration.
  void reset() {
    window.from_host(paint0);
    load.from_host(load0);
    store.clear();
    store.append(particles0);
    const test::Region r = test::region_around(particles0.x, 4.f);
    grid.build(ds.view(), 4.f, r.lo, r.hi, ws);
    grid.query_nearest(store.view(), 4.f);  // absorption needs the nearest sample within R_j < 1 cell
    env.paint = window.view();
    d.synchronize();
  }
};

TransferScene& scene() {
  static TransferScene s;
  return s;
}

template <typename F>
void run_stage(benchmark::State& state, F stage) {
  TransferScene& s = scene();
  for (auto _ : state) {
    state.PauseTiming();
    s.reset();
    state.ResumeTiming();
    stage(s);
    s.d.synchronize();
  }
}

void BM_TransferCapacity(benchmark::State& state) {
  run_stage(state, [](TransferScene& s) { s.transfer.update_capacity(s.ds.view(), s.load, s.env); });
  state.SetItemsProcessed(state.iterations() * scene().ds.view().count());
}
BENCHMARK(BM_TransferCapacity)->Unit(benchmark::kMicrosecond)->Iterations(20);

void BM_TransferAbsorb(benchmark::State& state) {
  TransferScene& s = scene();
  s.transfer.update_capacity(s.ds.view(), s.load, s.env);
  run_stage(state, [](TransferScene& sc) { sc.transfer.absorb(sc.ds.view(), sc.load, sc.store, 1.f / 60.f); });
  state.SetItemsProcessed(state.iterations() * s.store.size());
}
BENCHMARK(BM_TransferAbsorb)->Unit(benchmark::kMillisecond)->Iterations(20);

void BM_TransferDistance(benchmark::State& state) {
  run_stage(state, [](TransferScene& s) { s.transfer.update_distance(s.ds.view(), s.env); });
}
BENCHMARK(BM_TransferDistance)->Unit(benchmark::kMicrosecond)->Iterations(20);

void BM_TransferToGrid(benchmark::State& state) {
  TransferScene& s = scene();
  s.transfer.update_distance(s.ds.view(), s.env);
  run_stage(state, [](TransferScene& sc) { sc.transfer.particles_to_grid(sc.store, sc.env); });
}
BENCHMARK(BM_TransferToGrid)->Unit(benchmark::kMillisecond)->Iterations(20);

void BM_TransferEmit(benchmark::State& state) {
  TransferScene& s = scene();
  s.transfer.update_capacity(s.ds.view(), s.load, s.env);
  run_stage(state, [](TransferScene& sc) {
    TransferRecord rec;
    sc.transfer.emit(sc.ds.view(), sc.load, sc.store, sc.env, rec);
  });
}
BENCHMARK(BM_TransferEmit)->Unit(benchmark::kMillisecond)->Iterations(20);

void BM_TransferGridToParticles(benchmark::State& state) {
  TransferScene& s = scene();
  s.transfer.update_distance(s.ds.view(), s.env);
  int64_t made = 0;
  run_stage(state, [&](TransferScene& sc) {
    TransferRecord rec;
    sc.transfer.grid_to_particles(sc.store, sc.env, rec);
    made = rec.to_particles_count;
  });
  state.counters["particles_made"] = double(made);
}
BENCHMARK(BM_TransferGridToParticles)->Unit(benchmark::kMillisecond)->Iterations(20);

void BM_TransferStep(benchmark::State& state) {
  TransferScene& s = scene();
  TransferRecord last;
  run_stage(state, [&](TransferScene& sc) {
    last = sc.transfer.step(sc.ds.view(), sc.load, sc.store, sc.env);
    sc.transfer.collect(last);
  });
  state.counters["absorbed"] = double(last.absorbed_count);
  state.counters["emitted"] = double(last.emitted_count);
  state.counters["to_particles"] = double(last.to_particles_count);
  state.counters["to_grid"] = double(last.to_grid_count);
  state.counters["closure"] = last.max_closure_error();
  (void)s;
}
BENCHMARK(BM_TransferStep)->Unit(benchmark::kMillisecond)->Iterations(20);

}  // namespace
