// Helpers shared by the brush tests: poses and rotations.
#pragma once
#include "core/brush/brush_spec.h"
#include "core/math/vec.h"

namespace wb::test {

inline constexpr float kDt = 1.f / 60.f;

inline BrushPose make_pose(Vec3 p, Mat3 R = Mat3()) {
  BrushPose pose;
  pose.position = p;
  pose.rotation = R;
  return pose;
}
inline Mat3 rot_z(float deg) { return rotation_axis_angle(Vec3(0, 0, 1), deg * 3.14159265f / 180.f); }
inline Mat3 rot_x(float deg) { return rotation_axis_angle(Vec3(1, 0, 0), deg * 3.14159265f / 180.f); }

}  // namespace wb::test
