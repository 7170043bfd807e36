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
/// fields given, the object at `path` of file `source` (both named in messages; path "" for a
/// preset file's top level). Unknown keys are appended to `warnings` (when given); wrong types and
/// out-of-range values throw wb::Error.
BrushSpec brush_from_json(const nlohmann::json& j, const std::string& source, const std::string& path,
                          std::vector<std::string>* warnings = nullptr);

/// Throws wb::Error (prefixed by `context`) if a field is outside its documented range.
void validate_brush(const BrushSpec& brush, const std::string& context);

/// One row per numeric BrushSpec field: JSON key, valid range (inclusive), integer or not.
/// One brush field: its JSON key, range and what a person reads about it. The one range table of
/// the brush: the JSON reader and writer, validate_brush and the studio's brush panel take their
/// ranges from it (as the simulation parameters take theirs from param_table()).
struct BrushFieldRange {
  const char* key;
  double min;
  double max;
  bool integer;
  const char* label = "";    ///< short human name
  const char* unit = "";     ///< "cells", "" for dimensionless
  const char* paper = "";    ///< "Eq. 2", "§4.1", or "" when not from the paper
  const char* tooltip = "";  ///< one sentence on what it does
};
/// The table behind brush_from_json / validate_brush and the brush panel.
const std::vector<BrushFieldRange>& brush_field_ranges();
/// The row of `key`; throws wb::Error when there is none.
const BrushFieldRange& brush_field(const std::string& key);

}  // namespace wb
