#include "studio/preset.h"

#include "core/exec/error.h"

namespace wb::studio {

QualityPreset QualityPreset::cpu() {
  QualityPreset p;
  p.name = "CPU (light)";
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

QualityPreset QualityPreset::tiny() {
  QualityPreset p;
  p.name = "tiny";
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
  if (name == "auto") return for_device(d);
  if (name == "cpu") return cpu();
  if (name == "gpu") return gpu();
  if (name == "tiny") return tiny();
  WB_THROW("unknown quality preset '" + name + "' (valid: auto, cpu, gpu, tiny)");
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
