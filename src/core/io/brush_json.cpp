// Brush settings as JSON: one table of fields and ranges drives reading, writing and
// validation (paper §4.1; bristle counts and sizes per docs/FORMATS.md).
#include "core/io/brush_json.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <variant>

#include <nlohmann/json.hpp>

#include "core/exec/error.h"
#include "core/io/json_reader.h"

namespace wb {
namespace {

using Member = std::variant<int BrushSpec::*, float BrushSpec::*, uint32_t BrushSpec::*>;

struct Field {
  BrushFieldRange range;
  Member member;
};

const std::vector<Field>& fields() {
  static const std::vector<Field> table = {
      {{"bristles", 40, 600, true, "Bristles", "", "§4.1", "Number of bristles; more is slower"},
       &BrushSpec::bristles},
      {{"vertices_per_bristle", 4, 32, true, "Vertices per bristle", "", "§4.1",
        "Simulated vertices along each bristle (the chain of Eq. 2)"},
       &BrushSpec::vertices_per_bristle},
      {{"samples_per_bristle", 16, 256, true, "Samples per bristle", "", "§4.1",
        "Bristle samples that carry paint, along each bristle"},
       &BrushSpec::samples_per_bristle},
      {{"length", 1, 1000, false, "Length", "cells", "", "Bristle length (100 cells = 2 cm)"}, &BrushSpec::length},
      {{"width", 1, 1000, false, "Size", "cells", "", "Ferrule width across the handle (1 cell = 0.2 mm)"},
       &BrushSpec::width},
      {{"thickness", 1, 1000, false, "Thickness", "cells", "", "Ferrule thickness (flat and angular brushes)"},
       &BrushSpec::thickness},
      {{"length_variation", 0, 0.5, false, "Length variation", "", "", "Spread of bristle lengths, fraction"},
       &BrushSpec::length_variation},
      {{"stiffness", 0, 1, false, "Stiffness", "", "§4.1", "Bending stiffness (PBD bending constraint weight)"},
       &BrushSpec::stiffness},
      {{"stiffness_variation", 0, 0.9, false, "Stiffness variation", "", "", "Spread of bristle stiffness, fraction"},
       &BrushSpec::stiffness_variation},
      {{"bristle_radius", 0.01, 5, false, "Bristle radius", "cells", "Eq. 12",
        "Radius of one bristle (a clump of hairs when large): its paint capacity and boundary"},
       &BrushSpec::bristle_radius},
      // Paper Table 1 uses [0, 0.1]; 1 is plain Newtonian dynamics (Eq. 2), still valid.
      {{"beta_B", 0, 1, false, "\u03b2_B", "", "Eq. 2",
        "Inertial factor in the brush frame: 0 follows the handle rigidly, 1 is Newtonian (Table 1: 0-0.1)"},
       &BrushSpec::beta_B},
      // 1 would put the ferrule on the canvas at full pressure.
      {{"max_press", 0, 0.9, false, "Press depth", "", "", "How far full pressure presses the brush, of its length"},
       &BrushSpec::max_press},
      {{"seed", 0, 4294967295.0, true, "Seed", "", "", "Random seed of the bristle layout"}, &BrushSpec::seed},
  };
  return table;
}

double get_value(const BrushSpec& b, const Member& m) {
  return std::visit([&](auto p) { return double(b.*p); }, m);
}

void set_value(BrushSpec& b, const Member& m, double v) {
  std::visit(
      [&](auto p) {
        using T = std::remove_reference_t<decltype(b.*p)>;
        b.*p = T(v);
      },
      m);
}

}  // namespace

const std::vector<BrushFieldRange>& brush_field_ranges() {
  static const std::vector<BrushFieldRange> ranges = [] {
    std::vector<BrushFieldRange> r;
    for (const Field& f : fields()) r.push_back(f.range);
    return r;
  }();
  return ranges;
}

const BrushFieldRange& brush_field(const std::string& key) {
  for (const BrushFieldRange& r : brush_field_ranges())
    if (key == r.key) return r;
  WB_THROW("no brush field '" + key + "'");
}

nlohmann::json brush_to_json(const BrushSpec& brush) {
  nlohmann::json j = nlohmann::json::object();
  j["shape"] = to_string(brush.shape);
  for (const Field& f : fields()) {
    const double v = get_value(brush, f.member);
    if (f.range.integer)
      j[f.range.key] = int64_t(v);
    else
      j[f.range.key] = float_for_json(float(v));
  }
  return j;
}

void validate_brush(const BrushSpec& brush, const std::string& context) {
  for (const Field& f : fields()) {
    const double v = get_value(brush, f.member);
    if (!std::isfinite(v) || v < f.range.min || v > f.range.max)
      WB_THROW(context + "." + f.range.key + ": " + number_text(v) + " is outside [" + number_text(f.range.min) + ", " +
               number_text(f.range.max) + "]");
  }
}

BrushSpec brush_from_json(const nlohmann::json& j, const std::string& source, const std::string& path,
                          std::vector<std::string>* warnings) {
  ObjectReader r(j, source, path);
  BrushShape shape = BrushShape::Round;
  if (r.has("shape")) {
    try {
      shape = brush_shape_from_string(r.string("shape"));
    } catch (const Error& e) {
      std::string msg = e.what();
      if (const size_t tag = msg.rfind(" ["); tag != std::string::npos && msg.back() == ']') msg.resize(tag);
      r.fail(msg, "shape");
    }
  }
  BrushSpec b = default_brush(shape);
  for (const Field& f : fields()) {
    const BrushFieldRange& range = f.range;
    if (!r.has(range.key)) continue;
    const double v = r.number(range.key, range.min, range.max);  // a seed's range exceeds an int's
    if (range.integer && v != std::floor(v)) r.fail("expected an integer, found " + number_text(v), range.key);
    set_value(b, f.member, v);
  }
  if (warnings) r.warn_unknown(*warnings);
  return b;
}

}  // namespace wb
