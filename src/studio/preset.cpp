#include "studio/preset.h"

#include <algorithm>
#include <cmath>

#include "core/exec/error.h"

namespace wb::studio {

QualityPreset QualityPreset::cpu() {
  QualityPreset p;
  p.name = "CPU (light)";
  p.id = "cpu";
  p.bristles = 80;
  p.samples_per_bristle = 128;
  p.canvas_width = 1200;
  p.canvas_height = 900;
  p.canvas_depth = 32;
  p.palette_width = 320;
  p.palette_height = 200;
  p.ao_rays = 12;
  p.window_xy = 64;
  p.window_z = 16;
  // 8 candidates a cell instead of 27: a dab of paint on the palette, scrubbed, turned into
  // 700 000 particles at 27 (docs/perf/studio.md "The palette").
  p.candidate_split = 2;
  return p;
}

QualityPreset QualityPreset::gpu() {
  QualityPreset p;
  p.name = "GPU (paper)";
  p.id = "gpu";
  p.bristles = 400;
  p.samples_per_bristle = 128;
  p.canvas_width = 4096;
  p.canvas_height = 4096;
  p.canvas_depth = 64;
  p.palette_width = 640;
  p.palette_height = 400;
  p.ao_rays = 64;
  return p;
}

QualityPreset QualityPreset::fast() {
  QualityPreset p = cpu();
  p.name = "fast (40 bristles)";
  p.id = "fast";
  // What keeps up with the pen on two CPU cores (docs/STUDIO.md "Quality presets"): a round brush
  // of 40 bristles, about half the CPU preset's in each dimension, and a window to match. The
  // canvas and the palette are the CPU preset's, so a painting moves between the two.
  p.bristles = 40;
  p.brush_length = 48.f;
  p.brush_width = 20.f;
  p.samples_per_bristle = 64;  // samples_needed: a gap below one cell along the longest bristle
  p.ao_rays = 8;
  p.window_xy = 40;
  p.window_z = 12;
  return p;
}

QualityPreset QualityPreset::tiny() {
  QualityPreset p;
  p.name = "tiny";
  p.id = "tiny";
  p.bristles = 40;  // the fewest a brush file accepts
  p.brush_length = 16.f;
  p.brush_width = 8.f;
  p.samples_per_bristle = 24;  // gap below one cell along the longest bristle (16 x 1.16)
  p.canvas_width = 160;
  p.canvas_height = 120;
  p.canvas_depth = 16;
  p.palette_width = 112;
  p.palette_height = 80;
  p.ao_rays = 4;
  p.window_xy = 48;  // particles within D0's floor, about 8.6 cells, of the bristles (Simulator::place_window)
  p.window_z = 8;
  return p;
}

QualityPreset QualityPreset::from_name(const std::string& name, const Device& d) {
  if (name == "auto") return for_device(d, cpu_thread_count());
  if (name == "cpu") return cpu();
  if (name == "gpu") return gpu();
  if (name == "fast") return fast();
  if (name == "tiny") return tiny();
  WB_THROW("unknown quality preset '" + name + "' (valid: auto, cpu, gpu, fast, tiny)");
}

QualityPreset QualityPreset::for_device(const Device& d, int cpu_threads) {
  if (d.is_cuda()) return gpu();
  return cpu_threads >= 8 ? cpu() : fast();
}

Int3 QualityPreset::window() const { return Int3{window_xy, window_xy, std::min(window_z, canvas_depth)}; }

double estimated_step_ms(int64_t brush_samples, Int3 window) {
  // Fitted to the steps of `wetbrush bench bench/strokes/studio-demo.json` with the CPU preset's
  // brush and window (about 29 ms) and the fast preset's (about 9.4 ms), and to the same brush in
  // two windows (docs/STUDIO.md "Falling behind"): a fixed part, the brush's samples, the window's cells.
  constexpr double ms_fixed = 3.0, ms_per_sample = 1.69e-3, ms_per_cell = 1.36e-4;
  const double cells = double(window.x) * double(window.y) * double(window.z);
  return ms_fixed + ms_per_sample * double(brush_samples) + ms_per_cell * cells;
}

std::optional<QualityPreset> lighter_preset_that_keeps_up(int64_t brush_samples, Int3 window, double realtime_factor) {
  if (realtime_factor <= 0.0) return std::nullopt;
  const double now_ms = estimated_step_ms(brush_samples, window);
  std::optional<QualityPreset> best;
  double best_ms = 0.0;
  for (const QualityPreset& p : {QualityPreset::gpu(), QualityPreset::cpu(), QualityPreset::fast(), QualityPreset::tiny()}) {
    const double ms = estimated_step_ms(int64_t(p.bristles) * p.samples_per_bristle, p.window());
    if (ms >= now_ms || realtime_factor * now_ms / ms < 1.0) continue;
    if (!best || ms > best_ms) best = p, best_ms = ms;
  }
  return best;
}

int samples_needed(const BrushSpec& b) {
  return int(std::ceil(b.length * (1.f + 2.f * b.length_variation) * 1.05f)) + 4;
}

BrushSpec QualityPreset::start_brush() const {
  BrushSpec b = default_brush(BrushShape::Round);
  b.bristles = bristles;
  b.samples_per_bristle = samples_per_bristle;
  if (brush_length > 0.f) b.length = brush_length;
  if (brush_width > 0.f) b.width = b.thickness = brush_width;
  return b;
}

}  // namespace wb::studio
