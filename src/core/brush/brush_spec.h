// Brush description: the shape and size of the bristle bundle and its mechanical
// parameters (paper §4.1). A plain struct with defaults, == and JSON I/O, used by
// the stroke files, the CLI and the studio alike. Lengths are in canvas cells
// (1 cell = 0.2 mm).
#pragma once
#include <cstdint>
#include <string>

#include "core/math/vec.h"

namespace wb {

enum class BrushShape { Round, Flat, Fan, Filbert, Angular, Mop, Rigger };

const char* to_string(BrushShape s);
/// Parses "round", "flat", ... ; throws wb::Error naming the valid shapes otherwise.
BrushShape brush_shape_from_string(const std::string& s);

struct BrushSpec {
  BrushShape shape = BrushShape::Round;
  int bristles = 200;                ///< 40..600
  int vertices_per_bristle = 10;     ///< paper: 10
  int samples_per_bristle = 128;     ///< paper: 128 (gap below one cell)
  float length = 100.f;              ///< bristle length, cells (100 = 2 cm)
  float width = 40.f;                ///< ferrule width across the handle's x axis, cells
  float thickness = 40.f;            ///< ferrule size across the handle's y axis, cells
  float length_variation = 0.08f;    ///< relative spread of bristle lengths
  float stiffness = 0.7f;            ///< bending stiffness in [0, 1] (PBD bending constraint weight)
  float stiffness_variation = 0.15f; ///< relative spread of per-bristle stiffness
  float bristle_radius = 0.25f;      ///< radius of one bristle, cells (0.05 mm)
  float beta_B = 0.05f;              ///< Eq. 2 inertial factor, 0..0.1
  float max_press = 0.45f;           ///< pressure 1 lowers the ferrule by this fraction of the length
  uint32_t seed = 1;                 ///< per-bristle variation is deterministic from this

  bool operator==(const BrushSpec&) const = default;
};

/// Sensible defaults for each shape (sizes documented in docs/FORMATS.md).
BrushSpec default_brush(BrushShape shape);

/// Pose of the brush handle: the ferrule centre (where bristles are rooted) in canvas
/// cells, z = height above the canvas surface, and the rotation from the brush frame
/// to the canvas frame. At rest the bristles hang along -z of the brush frame.
struct BrushPose {
  Vec3 position{0.f, 0.f, 100.f};
  Mat3 rotation{};
  /// Eq. 1: R_B maps canvas to brush frame; x^B = R_B (x + c_B) with c_B = -position.
  WB_HD Mat3 R_B() const { return transpose(rotation); }
};

}  // namespace wb
