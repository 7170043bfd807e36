// The palette's scrub: the studio's fast preset's palette (a 320 x 200 glass, a round brush of 40
// bristles 48 cells long and 20 wide, a 40 x 40 x 12 window, 8 candidates a cell), two dabs put
// out and scrubbed together by three strokes across them, as the studio's demo does. The steps'
// mean against their median is the palette's tail; the viscous solve's iterations follow the
// depth of the dabs over the glass. Arg: the dabs' height in cells, 0 for palette_dab_size's.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "core/exec/device.h"
#include "core/session/session.h"

namespace {
void BM_PaletteScrub(benchmark::State& state) {
  wb::SimConfig c;
  c.device = wb::Device::from_env();
  c.canvas = wb::CanvasDims{320, 200, 32};
  c.brush = wb::default_brush(wb::BrushShape::Round);
  c.brush.bristles = 40;
  c.brush.samples_per_bristle = 64;
  c.brush.length = 48.f;
  c.brush.width = c.brush.thickness = 20.f;
  c.window = wb::Int3{40, 40, 12};
  c.params.transfer.candidate_split = 2;
  const wb::DabSize dab = wb::palette_dab_size(c);
  const float height = state.range(0) > 0 ? float(state.range(0)) : dab.height;
  const float pw = float(c.canvas.width), ph = float(c.canvas.height);
  std::vector<double> ms;
  double iterations = 0.0;
  int most = 0;
  for (auto _ : state) {
    state.PauseTiming();
    wb::Session s(c);
    wb::PaintLoad blue, yellow;
    blue.ryb[0] = 0.05f, blue.ryb[1] = 0.1f, blue.ryb[2] = 0.9f;
    yellow.ryb[0] = 0.05f, yellow.ryb[1] = 0.9f, yellow.ryb[2] = 0.05f;
    blue.load = yellow.load = 1.f;
    s.put_paint(0.35f * pw, 0.5f * ph, dab.radius, height, blue);
    s.put_paint(0.65f * pw, 0.5f * ph, dab.radius, height, yellow);
    ms.clear();
    iterations = 0.0, most = 0;
    state.ResumeTiming();
    for (int k = 0; k < 3; ++k) {
      // The demo's strokes: 40 pen events 16 ms apart across both dabs, back and forth.
      wb::Stroke st;
      st.canvas = s.dims();
      st.brush = c.brush;
      st.paint.load = 0.f;
      st.paint.reload_on_pen_down = false;
      const float y = ph * (0.5f + 0.04f * float(k - 1));
      const float x0 = pw * (k % 2 ? 0.8f : 0.2f), x1 = pw * (k % 2 ? 0.2f : 0.8f);
      for (int i = 0; i <= 40; ++i) {
        wb::PenSample q;
        q.t = 0.016 * i;
        q.x = x0 + (x1 - x0) * float(std::min(i, 39)) / 39.f;
        q.y = y;
        q.pressure = i < 40 ? 0.6f : 0.f;
        q.down = i < 40;
        q.tilt_x = k % 2 ? -15.f : 15.f;
        st.samples.push_back(q);
      }
      s.begin_replay(st);
      for (;;) {
        const auto t0 = std::chrono::steady_clock::now();
        if (!s.advance()) break;
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        const int it = s.sim().grid().stats().viscosity_iterations;
        iterations += it, most = std::max(most, it);
      }
    }
  }
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  double mean = 0.0;
  for (double v : ms) mean += v;
  mean /= double(std::max<size_t>(ms.size(), 1));
  state.counters["height"] = height;
  state.counters["steps"] = double(ms.size());
  state.counters["step_mean_ms"] = mean;
  state.counters["step_median_ms"] = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  state.counters["cg_mean"] = iterations / double(std::max<size_t>(ms.size(), 1));
  state.counters["cg_most"] = most;
}
BENCHMARK(BM_PaletteScrub)->Arg(0)->Arg(12)->Iterations(1)->Unit(benchmark::kMillisecond);
}  // namespace
