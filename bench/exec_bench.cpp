// Device-wide primitives on the per-step path, on the device named by WB_DEVICE: the particles'
// sort by cell (330 K keys of 22 bits, nearly sorted as a step leaves them) and the viscous
// solve's scan of a flag a face (3.5 M faces of a 192 x 192 x 32 window).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "core/exec/algorithms.h"
#include "core/exec/buffer.h"
#include "core/exec/device.h"
#include "core/exec/workspace.h"

namespace {
using namespace wb;

void BM_SortByKey(benchmark::State& state) {
  const Device d = Device::from_env();
  Workspace ws(d);
  const int64_t n = 330000;
  std::mt19937 rng(7);
  std::vector<uint32_t> keys(n), values(n);
  // Sorted keys, a tenth of them moved to a neighbouring half cell: a step's particles.
  for (int64_t i = 0; i < n; ++i) keys[i] = uint32_t(i * 12);
  for (int64_t i = 0; i < n; i += 10) keys[i] += rng() % 64;
  DeviceBuffer<uint32_t> k(d, n), v(d, n);
  for (auto _ : state) {
    state.PauseTiming();
    k.copy_from_host(keys);
    v.copy_from_host(values);
    d.synchronize();
    state.ResumeTiming();
    sort_by_key(d, k.data(), v.data(), n, 22, ws);
    d.synchronize();
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_SortByKey)->Unit(benchmark::kMicrosecond);

void BM_ExclusiveScan(benchmark::State& state) {
  const Device d = Device::from_env();
  Workspace ws(d);
  const int64_t n = 192 * 192 * 32 * 3;
  std::vector<uint32_t> flags(n);
  for (int64_t i = 0; i < n; ++i) flags[i] = (i / 4096) % 3 == 0 ? 1u : 0u;
  DeviceBuffer<uint32_t> in(d, n), out(d, n);
  in.copy_from_host(flags);
  for (auto _ : state) {
    exclusive_scan_into(d, in.data(), out.data(), n, ws);
    d.synchronize();
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_ExclusiveScan)->Unit(benchmark::kMicrosecond);

}  // namespace
