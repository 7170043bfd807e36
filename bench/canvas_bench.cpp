// Gather and scatter of the default 128 x 128 x 32 window on the default canvas.
#include <benchmark/benchmark.h>

#include "core/canvas/tile_store.h"
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
