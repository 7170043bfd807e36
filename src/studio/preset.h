// The studio's quality presets: brush resolution, canvas, palette, window and render settings
// sized for the device (docs/STUDIO.md "Quality presets").
#pragma once
#include <string>

#include "core/brush/brush_spec.h"
#include "core/exec/device.h"

namespace wb::studio {

/// A quality preset: brush resolution, canvas and render settings sized for the device.
struct QualityPreset {
  std::string name;
  int bristles = 80;
  int samples_per_bristle = 32;
  int canvas_width = 1200, canvas_height = 900, canvas_depth = 32;
  int palette_width = 320, palette_height = 200;  ///< the palette's own canvas, cells (same depth)
  int ao_rays = 12;
  int window_xy = 128, window_z = 32;  ///< active simulation window, cells (paper: 128 x 128 x 32)
  float brush_length = 0.f, brush_width = 0.f;  ///< starting round brush size, cells (0: the shape's default)
  /// Candidates per cell axis of Eq. 15's sampling (transfer.candidate_split; 3: the paper's 27).
  int candidate_split = 3;
  /// The starting brush: a round brush with the preset's bristles, samples and size.
  BrushSpec start_brush() const;
  static QualityPreset cpu();
  static QualityPreset gpu();
  /// A small, fast configuration (small canvas, window and brush) for tests and slow machines:
  /// the same studio and the same physics, at a scale where a stroke takes seconds on two cores.
  static QualityPreset tiny();
  /// "cpu", "gpu", "tiny"; "auto" picks from the device. Throws wb::Error for other names.
  static QualityPreset from_name(const std::string& name, const Device& d);
  static QualityPreset for_device(const Device& d) { return d.is_cuda() ? gpu() : cpu(); }
};

}  // namespace wb::studio
