// Stroke input (Figure 4 step 1: the brush pose comes from the input): a recorded stroke
// with its canvas, brush, paint on the brush, timed pen samples and timed paint events.
// Read from the JSON stroke format or from MyPaint `t x y pressure` event dumps; the
// formats, ranges, clamps and errors are specified in docs/FORMATS.md.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/brush/brush_spec.h"
#include "core/canvas/tile_store.h"
#include "core/io/pen_sample.h"
#include "core/transfer/paint_load.h"

namespace wb {

/// The longest span of samples a stroke may have, seconds (a week): validate_stroke refuses a
/// longer recording (its pauses replay fast-forwarded, its strokes do not).
inline constexpr double kMaxStrokeSeconds = 7.0 * 24.0 * 3600.0;

enum class StrokeEventKind {
  Dip,    ///< dip the brush into a palette well: load paint `ryb`/`oil` up to `load`
  Wipe,   ///< wipe the brush on a rag: remove `fraction` of the paint it carries
  Clean,  ///< clean the brush in solvent: remove all paint
  Dry,    ///< let the canvas dry (every painted cell becomes solid)
};
const char* to_string(StrokeEventKind k);

/// A timed action between or during pen movements.
struct StrokeEvent {
  StrokeEventKind kind = StrokeEventKind::Dip;
  double t = 0.0;                        ///< seconds, on the samples' clock
  float ryb[3] = {0.f, 0.f, 0.f};        ///< Dip: pigment
  float oil = 0.3f;                      ///< Dip: oil fraction
  float load = 1.f;                      ///< Dip: fill to this fraction of capacity
  float fraction = 0.5f;                 ///< Wipe: fraction of the carried paint removed
  bool operator==(const StrokeEvent&) const = default;
};

/// A complete stroke recording, validated: samples strictly increasing in t, every value
/// finite and in range, every sample on the canvas.
struct Stroke {
  CanvasDims canvas{};
  std::optional<std::array<float, 3>> paper_rgb;  ///< paper colour, linear RGB in [0, 1]
  std::optional<CanvasGround> ground;             ///< the canvas's priming (ground.h); unset: bare
  /// The canvas's tilt from the horizontal, degrees in [0, 90] (GridParams::tilt); unset: the
  /// replayer's parameters (flat on a table by default).
  std::optional<float> tilt;
  BrushSpec brush{};
  PaintLoad paint{};
  std::vector<PenSample> samples;
  std::vector<StrokeEvent> events;  ///< sorted by t (non-decreasing)

  // Simulation settings for replay (docs/FORMATS.md, "simulation").
  double dt = 1.0 / 60.0;             ///< step length, seconds
  float max_move_per_substep = 3.f;   ///< cells a brush point may move in one sub-step (docs/FORMATS.md)
  int max_substeps = 64;              ///< cap on sub-steps per step
  double lead_in = 0.25;              ///< seconds the brush descends from the air to the first sample
  double lead_out = 0.25;             ///< seconds it rises after the last sample
  /// Active window X, Y, Z cells the stroke needs (a brush that splays wider than the default
  /// 160 x 160 x 32); unset: the replayer's default. `replay --window` overrides it.
  std::optional<std::array<int, 3>> window;

  std::string source;                 ///< file it was read from (for messages)
  std::vector<std::string> warnings;  ///< non-fatal findings while reading (unknown keys, clamps)

  /// Seconds from the first to the last sample (0 for one sample or none).
  double duration() const { return samples.size() < 2 ? 0.0 : samples.back().t - samples.front().t; }
};

/// Reads a stroke file, detecting the format: a JSON object (first non-blank byte '{')
/// is the wetbrush stroke format, anything else textual is a MyPaint event dump.
/// Throws wb::Error naming the file and the line / sample on any problem.
Stroke load_stroke(const std::string& path);

/// What load_stroke does with the file's text: rejects binary data, then reads the format the
/// first non-blank byte names. `source` names it in messages.
Stroke parse_stroke_text(std::string_view text, const std::string& source);
/// The JSON stroke format from text; `source` names it in messages.
Stroke parse_stroke_json(std::string_view text, const std::string& source);
/// MyPaint event dump (`t x y pressure [xtilt ytilt]` per line) from text.
Stroke parse_mypaint_events(std::string_view text, const std::string& source);

/// The JSON text of a stroke (format version 1), one sample per line.
std::string stroke_to_json_string(const Stroke& stroke);
/// Writes the stroke atomically: `path.tmp`, fsync, rename over `path`.
void save_stroke_json(const Stroke& stroke, const std::string& path);

/// Checks the invariants listed on Stroke (used by both readers and before saving);
/// throws wb::Error naming `stroke.source` and the offending sample or event.
void validate_stroke(const Stroke& stroke);

/// Version of the JSON stroke format this build reads and writes.
inline constexpr int kStrokeFormatVersion = 1;

}  // namespace wb
