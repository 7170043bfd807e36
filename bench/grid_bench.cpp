// Grid stage (paper §4.2) on the default 128 x 128 x 32 window: per-stage times of one
// step with a paint layer and a pressed brush (the solver study's scene), and the window
// move (scatter + velocity shift + gather).
#include <benchmark/benchmark.h>

#include <vector>

#include "core/exec/device.h"
#include "core/canvas/tile_store.h"
#include "core/grid/solver_study.h"
#include "core/particles/particles.h"

namespace {

wb::StudyScene& scene() {
  static wb::StudyScene s(wb::Device::from_env(), 128);
  static bool ready = false;
  if (!ready) {
    s.prepare_system(2);
    ready = true;
  }
  return s;
}

/// Puts the scene's paint and velocity back as they were when it leaves scope: a stage that
/// changes them (advection, forces) leaves the next benchmark the scene the others measure.
class KeepScene {
 public:
  explicit KeepScene(wb::Grid& g) : g_(g), paint_(g.window().paint().to_host()) {
    for (int c = 0; c < 3; ++c) vel_[c] = g.window().velocity(c).to_host();
  }
  ~KeepScene() {
    g_.window().paint().from_host(paint_);
    for (int c = 0; c < 3; ++c) g_.window().velocity(c).copy_from_host(vel_[c]);
  }
  KeepScene(const KeepScene&) = delete;
  KeepScene& operator=(const KeepScene&) = delete;

 private:
  wb::Grid& g_;
  std::vector<std::vector<float>> paint_;
  std::vector<float> vel_[3];
};

void BM_GridMoveWindow(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const wb::Int3 o = g.window().origin();
  int step = 0;
  for (auto _ : state) {
    g.move_window(wb::Int3{o.x + ((step & 1) ? 8 : 0), o.y, 0});
    ++step;
  }
  g.move_window(o);
}
BENCHMARK(BM_GridMoveWindow)->Unit(benchmark::kMillisecond);

void BM_GridClassify(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  for (auto _ : state) g.classify();
}
BENCHMARK(BM_GridClassify)->Unit(benchmark::kMillisecond);

void BM_GridAdvect(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const KeepScene keep(g);
  g.classify();
  for (auto _ : state) g.advect(g.params().dt);
  g.read_record();
  state.counters["courant"] = g.stats().advect_courant;
}
BENCHMARK(BM_GridAdvect)->Unit(benchmark::kMillisecond);

void BM_GridForces(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const KeepScene keep(g);
  g.classify();
  for (auto _ : state) g.add_external_forces(g.params().dt);
}
BENCHMARK(BM_GridForces)->Unit(benchmark::kMillisecond);

void BM_GridRheology(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  g.classify();
  for (auto _ : state) g.rheology();
}
BENCHMARK(BM_GridRheology)->Unit(benchmark::kMillisecond);

void BM_GridViscosity(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  g.classify();
  g.rheology();
  g.add_external_forces(g.params().dt);
  // Every iteration solves from the same forced velocity (a solve from its own answer is free).
  std::vector<float> start[3];
  for (int c = 0; c < 3; ++c) start[c] = g.window().velocity(c).to_host();
  for (auto _ : state) {
    state.PauseTiming();
    for (int c = 0; c < 3; ++c) g.window().velocity(c).copy_from_host(start[c]);
    state.ResumeTiming();
    g.apply_viscosity(g.params().dt);
  }
  g.read_record();  // the solve's faces, iterations and residual stay on the device until read
  state.counters["faces"] = g.stats().viscosity_faces;
  state.counters["cg_iterations"] = g.stats().viscosity_iterations;
  state.counters["residual"] = g.stats().viscosity_residual;
}
BENCHMARK(BM_GridViscosity)->Unit(benchmark::kMillisecond);

/// Arg: 0 fixed point (L = 3), 1 Jacobi (6), 2 Chebyshev (6 sweeps, rho estimated by 30 sweeps).
void BM_GridProject(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const KeepScene keep(g);
  const wb::GridParams saved = g.params();
  g.params().solver = state.range(0) == 0   ? wb::PressureSolver::FixedPoint
                      : state.range(0) == 1 ? wb::PressureSolver::Jacobi
                                            : wb::PressureSolver::Chebyshev;
  g.classify();
  for (auto _ : state) g.project(g.params().dt);
  g.params() = saved;
}
BENCHMARK(BM_GridProject)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_GridDry(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const KeepScene keep(g);
  for (auto _ : state) g.dry(g.params().dt);
}
BENCHMARK(BM_GridDry)->Unit(benchmark::kMillisecond);

void BM_GridStep(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const KeepScene keep(g);
  for (auto _ : state) g.step(g.params().dt);
}
BENCHMARK(BM_GridStep)->Unit(benchmark::kMillisecond);

// The passes down every column of the window (docs/PERFORMANCE.md "Column scans"): the tops of
// the paint and particles (twice a step), the particles' floor and free surface, and their ground,
// on the scene's wavy layer about 8 cells deep under 24 layers of air, with particles in a
// quarter of the columns. Arg: 0 all three, 1 the tops, 2 the floor, 3 the ground.
void BM_ColumnScans(benchmark::State& state) {
  wb::Grid& g = scene().grid();
  const wb::Device d = g.device();
  const wb::GridDims gd = g.dims();
  const int64_t columns = int64_t(gd.nx) * gd.ny;
  wb::PaintWindow& paint = g.window().paint();
  std::vector<float> pd(size_t(gd.cells()), 0.f);
  for (int64_t c = 0; c < columns; c += 4) pd[size_t(10 * columns + c)] = 0.6f;  // a particle in layer 10
  wb::DeviceBuffer<float> particles(d, pd.size()), out(d, size_t(6 * columns));
  particles.copy_from_host(pd);
  const float liquid = g.params().liquid_threshold, dry = g.params().dry_threshold;
  const int which = int(state.range(0));
  for (auto _ : state) {
    if (which == 0 || which == 1)
      wb::grid_column_tops(d, gd, paint.density.data(), paint.dryness.data(), dry, particles.data(), 0.f, out.data());
    if (which == 0 || which == 2)
      wb::particles_solid_height(d, paint.view(), particles.data(), dry, liquid, 0.f, out.data(), out.data() + columns);
    if (which == 0 || which == 3)
      wb::particles_ground_surface(d, paint.view(), particles.data(), dry, liquid, 0.f, out.data());
    d.synchronize();
  }
}
BENCHMARK(BM_ColumnScans)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

// A step's cost must not grow with the painting: a 64 x 64 x 16 window with a 4-cell layer on a
// canvas that holds state.range(0) painted tiles elsewhere (a 2-cell layer each; 10^4 tiles are
// 570 MB of canvas). Drying on, as in the simulator.
void BM_GridStepOnAPaintedCanvas(benchmark::State& state) {
  const wb::Device device = wb::Device::from_env();
  wb::TileStore canvas(device, wb::CanvasDims{2048, 2048, 16});
  const int tiles = int(state.range(0));
  for (int t = 0; t < tiles; ++t) {
    const int id = canvas.tiles_x() * canvas.tiles_y() - 1 - t;  // from the far corner inwards
    wb::TileData d = canvas.read_tile(id);
    d.tile_x = id % canvas.tiles_x();
    d.tile_y = id / canvas.tiles_x();
    for (size_t i = 0; i < 2 * size_t(wb::kTileSize) * wb::kTileSize; ++i) d.density[i] = 1.f;
    canvas.write_tile(d);
  }
  wb::Grid g(canvas, wb::GridParams{}, wb::Int3{64, 64, 16}, wb::Int3{32, 32, 0});
  const wb::GridDims gd = g.dims();
  std::vector<std::vector<float>> f(wb::kPaintFieldCount, std::vector<float>(size_t(gd.cells()), 0.f));
  for (int64_t c = 0; c < gd.cells(); ++c)
    if (c < 4 * int64_t(gd.nx) * gd.ny) f[0][size_t(c)] = 1.f, f[4][size_t(c)] = 0.3f;
  g.window().paint().from_host(f);
  for (auto _ : state) g.step(g.params().dt);
  state.counters["painted_tiles"] = double(canvas.allocated_tiles());
}
BENCHMARK(BM_GridStepOnAPaintedCanvas)->Arg(0)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
