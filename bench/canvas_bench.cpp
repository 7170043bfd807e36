// Gather and scatter of the default 128 x 128 x 32 window on the default canvas; undo's capture.
#include <benchmark/benchmark.h>

#include "core/canvas/ground.h"
#include "core/canvas/tile_store.h"
#include "core/io/undo_tiles.h"
#include "core/exec/device.h"

namespace {
void BM_WindowGatherScatter(benchmark::State& state) {
  const wb::Device d = wb::Device::from_env();
  wb::TileStore canvas(d, wb::CanvasDims{});
  wb::PaintWindow w(d, wb::Int3{128, 128, 32});
  std::vector<std::vector<float>> f(wb::kPaintFieldCount, std::vector<float>(size_t(w.cell_count()), 0.25f));
  w.from_host(f);
  w.set_origin({1000, 1000, 0});
  canvas.scatter(w);
  int step = 0;
  for (auto _ : state) {
    w.set_origin({1000 + (step % 8), 1000 + (step % 5), 0});
    canvas.gather(w);
    canvas.scatter(w);
    d.synchronize();
    ++step;
  }
  state.SetItemsProcessed(state.iterations() * w.cell_count());
}
BENCHMARK(BM_WindowGatherScatter)->Unit(benchmark::kMicrosecond);
}  // namespace

// Undo's capture at a stroke's first step (Session::capture_before_step): the tiles around the
// brush on a linen canvas, where every tile holds the ground, snapshotted (compressed) before it.
namespace {
void BM_UndoCaptureOnLinen(benchmark::State& state) {
  const wb::Device d = wb::Device::from_env();
  const int side = int(state.range(0));
  wb::TileStore canvas(d, wb::CanvasDims{side, side, 32});
  canvas.lay_weave(wb::weave_field(wb::CanvasGround::of(wb::Weave::Linen), 2e-4f, wb::Vec3(0.1f, 0.1f, 0.1f)));
  for (auto _ : state) {
    wb::StrokeTileRecorder r;
    r.capture_rect(canvas, side / 2 - 100, side / 2 - 100, side / 2 + 100, side / 2 + 100);
    benchmark::DoNotOptimize(r.captured());
  }
}
BENCHMARK(BM_UndoCaptureOnLinen)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond);
}  // namespace
