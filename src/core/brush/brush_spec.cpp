// Brush presets (paper §4.1, §7: brushes of 40 to 600 bristles, 10 vertices and 128
// samples each). Sizes are in canvas cells (1 cell = 0.2 mm); the table with the same
// numbers in millimetres is in docs/BRUSH.md.
#include "core/brush/brush_spec.h"

#include <string>

#include "core/exec/error.h"

namespace wb {

namespace {
struct ShapeName {
  BrushShape shape;
  const char* name;
};
constexpr ShapeName kShapeNames[] = {
    {BrushShape::Round, "round"},     {BrushShape::Flat, "flat"}, {BrushShape::Fan, "fan"},
    {BrushShape::Filbert, "filbert"}, {BrushShape::Angular, "angular"}, {BrushShape::Mop, "mop"},
    {BrushShape::Rigger, "rigger"},
};
}  // namespace

const char* to_string(BrushShape s) {
  for (const auto& e : kShapeNames)
    if (e.shape == s) return e.name;
  return "unknown";
}

BrushShape brush_shape_from_string(const std::string& s) {
  for (const auto& e : kShapeNames)
    if (s == e.name) return e.shape;
  std::string valid;
  for (const auto& e : kShapeNames) valid += std::string(valid.empty() ? "" : ", ") + e.name;
  WB_THROW("unknown brush shape '" + s + "' (valid: " + valid + ")");
}

BrushSpec default_brush(BrushShape shape) {
  BrushSpec b;
  b.shape = shape;
  switch (shape) {
    case BrushShape::Round:  // 8 mm round, 20 mm long, tapering to a point
      b.bristles = 200;
      b.length = 100.f;
      b.width = b.thickness = 40.f;
      b.stiffness = 0.7f;
      break;
    case BrushShape::Flat:  // 12 mm x 2.4 mm ferrule, square tip
      // Each simulated bristle is a wet clump of hairs (the paper's brushes have 40-600): 120
      // clumps of 0.34 cells, spaced about 2.5 cells as the round's bristles are, so the 0.2 mm
      // grid resolves their tracks as streaks; 300 bristles 1.5 cells apart left none
      // (docs/TRANSFER.md "Bristle streaks"). Their load capacity is the 300 bristles' (M_max
      // scales with the radius cubed: TransferParams::for_bristle_radius).
      b.bristles = 120;
      b.bristle_radius = 0.34f;
      b.length = 90.f;
      b.width = 60.f;
      b.thickness = 12.f;
      b.stiffness = 0.75f;
      break;
    case BrushShape::Fan:  // one thin row of bristles spread in angle
      b.bristles = 150;
      b.length = 100.f;
      b.width = 50.f;
      b.thickness = 6.f;
      b.stiffness = 0.6f;
      break;
    case BrushShape::Filbert:  // flat with an oval tip
      b.bristles = 300;
      b.length = 95.f;
      b.width = 56.f;
      b.thickness = 12.f;
      b.stiffness = 0.7f;
      break;
    case BrushShape::Angular:  // flat with lengths falling linearly across the width
      b.bristles = 300;
      b.length = 100.f;
      b.width = 60.f;
      b.thickness = 12.f;
      b.stiffness = 0.75f;
      break;
    case BrushShape::Mop:  // big, soft, slightly splayed
      b.bristles = 600;
      b.length = 100.f;
      b.width = b.thickness = 70.f;
      b.stiffness = 0.3f;
      b.stiffness_variation = 0.25f;
      b.length_variation = 0.1f;
      break;
    case BrushShape::Rigger:  // long and thin liner, few bristles
      b.bristles = 40;
      b.length = 110.f;
      b.width = b.thickness = 8.f;
      b.stiffness = 0.55f;
      b.length_variation = 0.05f;
      break;
  }
  return b;
}

}  // namespace wb
