// The studio's quality presets: brush resolution, canvas, palette, window and render settings
// sized for the device (docs/STUDIO.md "Quality presets").
#pragma once
#include <optional>
#include <string>

#include "core/brush/brush_spec.h"
#include "core/exec/device.h"
#include "core/canvas/window.h"

namespace wb::studio {

/// A quality preset: brush resolution, canvas and render settings sized for the device.
struct QualityPreset {
  std::string name;
  std::string id;  ///< its --preset name: cpu, gpu, fast, tiny
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
  /// The CPU preset's canvas with a smaller brush of fewer bristles and a smaller window: keeps up
  /// with the pen on two CPU cores.
  static QualityPreset fast();
  /// A small, fast configuration (small canvas, window and brush) for tests and slow machines:
  /// the same studio and the same physics, at a scale where a stroke takes seconds on two cores.
  static QualityPreset tiny();
  /// "cpu", "gpu", "fast", "tiny"; "auto" picks from the device and the CPU's threads
  /// (for_device). Throws wb::Error for other names.
  static QualityPreset from_name(const std::string& name, const Device& d);
  /// The GPU preset on a GPU; on the CPU, the CPU preset with 8 threads or more and the fast
  /// preset below (docs/STUDIO.md "Quality presets": the CPU preset's step on two cores is two to
  /// three times the real-time budget).
  static QualityPreset for_device(const Device& d, int cpu_threads);
  /// The simulated window of this preset, cells.
  Int3 window() const;
};

/// The samples a bristle of brush `b` needs: the brush model requires a gap below one cell along
/// the longest bristle (length x (1 + 2 length_variation)), with a margin.
int samples_needed(const BrushSpec& b);

/// A step's wall time estimated from what it simulates: `brush_samples` (bristles x samples a
/// bristle) and the window's cells, ms on the CPU backend of the 2-core VM. Fitted to the CPU
/// preset's and the fast preset's measured steps (docs/STUDIO.md "Falling behind"); what it is
/// for is the ratio of two configurations' costs.
double estimated_step_ms(int64_t brush_samples, Int3 window);

/// The preset of the most detail, lighter than what is simulated now (`brush_samples`, `window`),
/// whose estimated real-time factor reaches 1, given the factor `realtime_factor` measured now;
/// nothing when no lighter preset would keep up.
std::optional<QualityPreset> lighter_preset_that_keeps_up(int64_t brush_samples, Int3 window, double realtime_factor);

}  // namespace wb::studio
