// Pen to brush pose (Figure 4 step 1, paper §4.1: the brush frame of Eq. 1 follows the
// handle): x, y place the handle, pressure lowers it, tilt tilts it, twist rolls it about
// its axis. Geometry and clamps are documented in docs/FORMATS.md ("Pen to brush pose").
#pragma once
#include "core/brush/brush_spec.h"
#include "core/io/pen_sample.h"
#include "core/math/vec.h"

namespace wb {

/// Tilt beyond this (degrees from vertical) is clamped: past it a real handle and ferrule
/// would meet the canvas before the bristles do, and the tan() mapping diverges at 90°.
inline constexpr float kMaxTiltDeg = 80.f;
/// A lifted pen holds the ferrule this fraction of the bristle length above touching.
inline constexpr float kPenUpLift = 0.5f;

/// Elevation parameter e that the player interpolates: the pressure (0..1) when the pen is
/// down, -1 when it is up. e >= 0 means the rest-shape tip touches or presses the canvas.
float pen_elevation(const PenSample& s);

/// Distance from the canvas along the handle axis to the ferrule centre:
/// e in [0, 1]: L_eff = length (1 - e max_press); e in [-1, 0): length (1 - e kPenUpLift).
float handle_distance(float elevation, const BrushSpec& brush);

/// Unit handle axis (from the canvas toward the handle) for Qt-style tilt angles in
/// degrees: its projections on the x-z and y-z planes make tilt_x and tilt_y with +z,
/// i.e. a = normalize(tan tilt_x, tan tilt_y, 1), the polar angle clamped to kMaxTiltDeg.
Vec3 handle_axis(float tilt_x_deg, float tilt_y_deg);

/// Brush-to-canvas rotation: the minimal rotation taking +z to the handle axis, then a
/// right-handed roll by `twist_deg` about that axis. Columns: brush x, y, z (= axis).
Mat3 brush_rotation(float tilt_x_deg, float tilt_y_deg, float twist_deg);

/// Pose with the elevation given explicitly (the player interpolates it between samples).
/// position = (x, y, 0) + axis * handle_distance(elevation), rotation = brush_rotation(...).
BrushPose pose_from_pen(const PenSample& s, float elevation, const BrushSpec& brush);
/// Pose of one pen sample: pose_from_pen(s, pen_elevation(s), brush).
BrushPose pose_from_pen(const PenSample& s, const BrushSpec& brush);

}  // namespace wb
