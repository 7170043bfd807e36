// Brush settings as JSON (the "brush" object of stroke files, brush presets): every field
// of BrushSpec with its valid range (paper §4.1 brush model, Table 1 sizes).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/brush/brush_spec.h"

namespace wb {

/// All fields, shape as its name ("round", "flat", ...).
nlohmann::json brush_to_json(const BrushSpec& brush);

/// Starts from default_brush(shape) ("shape" optional, default "round") and overrides the
/// fields given. `context` prefixes messages (e.g. "stroke.json: brush"). Unknown keys are
/// appended to `warnings` (when given); wrong types and out-of-range values throw wb::Error.
BrushSpec brush_from_json(const nlohmann::json& j, const std::string& context,
                          std::vector<std::string>* warnings = nullptr);

/// Throws wb::Error (prefixed by `context`) if a field is outside its documented range.
void validate_brush(const BrushSpec& brush, const std::string& context);

/// One row per numeric BrushSpec field: JSON key, valid range (inclusive), integer or not.
struct BrushFieldRange {
  const char* key;
  double min;
  double max;
  bool integer;
};
/// The table behind brush_from_json / validate_brush (also used to write docs and UIs).
const std::vector<BrushFieldRange>& brush_field_ranges();

}  // namespace wb
