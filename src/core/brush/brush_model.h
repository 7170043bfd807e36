// Brush model (paper §4.1, Figure 5): where each bristle is rooted in the ferrule, its
// rest direction, rest length and stiffness, by shape. Host-side and deterministic
// from BrushSpec::seed; the Brush uploads it once.
#pragma once
#include <cstdint>
#include <vector>

#include "core/brush/brush_spec.h"
#include "core/math/vec.h"

namespace wb {

struct BristleLayout {
  int bristles = 0;
  int per_bristle = 0;
  std::vector<Vec3> root;         ///< per bristle, brush frame (z = 0: the ferrule's mouth)
  std::vector<Vec3> dir;          ///< per bristle, unit rest direction (brush frame, -z is down)
  std::vector<float> length;      ///< per bristle, rest length, cells
  std::vector<float> stiffness;   ///< per bristle, in [0, 1] (per step at the reference iteration count)
  std::vector<Vec3> rest;         ///< per vertex (k * per_bristle + i): rest position, brush frame
  /// Smallest distance between rest vertices of different bristles, capped at
  /// 2 * bristle_radius (cells).
  float min_rest_spacing = 0.f;
};

/// Validates the spec (throws wb::Error naming the field) and builds its bristles.
BristleLayout build_bristle_layout(const BrushSpec& spec);

/// How much of each bristle sample's paint a dip reaches, in [0, 1], per sample
/// (k * samples_per_bristle + j, j = 0 at the root): the brush pushed `depth` cells into a pile
/// of paint tip first, in its rest pose. Linear in the sample's height above the tuft's lowest
/// tip (1 there, 0 at `depth`) times the bristle's exposure in the tuft (1 on its outline, a
/// third on its axis, by the root's elliptic radius). docs/TRANSFER.md "Dipping".
std::vector<float> dip_exposure(const BristleLayout& layout, int samples_per_bristle, float depth);

/// Length profile of the shape at a root (x across the width, in [-width/2, width/2]),
/// as a fraction of spec.length: 1 for most shapes; oval for filbert; linear for angular.
float shape_length_profile(BrushShape shape, float x, float width);

}  // namespace wb
