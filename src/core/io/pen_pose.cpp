// Pen to brush pose (paper §4.1, Eq. 1: the brush frame R_B, c_B comes from the handle).
#include "core/io/pen_pose.h"

#include <cmath>

namespace wb {
namespace {
constexpr float kDegToRad = 3.14159265358979323846f / 180.f;
}

float pen_elevation(const PenSample& s) { return s.down ? s.pressure : -1.f; }

float handle_distance(float elevation, const BrushSpec& brush) {
  const float e = clampf(elevation, -1.f, 1.f);
  if (e >= 0.f) return brush.length * (1.f - e * brush.max_press);
  return brush.length * (1.f - e * kPenUpLift);
}

Vec3 handle_axis(float tilt_x_deg, float tilt_y_deg) {
  const float tx = clampf(tilt_x_deg, -kMaxTiltDeg, kMaxTiltDeg) * kDegToRad;
  const float ty = clampf(tilt_y_deg, -kMaxTiltDeg, kMaxTiltDeg) * kDegToRad;
  const float px = tanf(tx), py = tanf(ty);
  const float horiz = sqrtf(px * px + py * py);  // tan of the polar angle
  const float max_polar = kMaxTiltDeg * kDegToRad;
  if (horiz <= tanf(max_polar)) return normalize(Vec3(px, py, 1.f));
  // Both tilts large: keep the azimuth, clamp the angle from vertical.
  const float s = sinf(max_polar) / horiz;
  return Vec3(px * s, py * s, cosf(max_polar));
}

Mat3 brush_rotation(float tilt_x_deg, float tilt_y_deg, float twist_deg) {
  const Vec3 a = handle_axis(tilt_x_deg, tilt_y_deg);
  // Swing: +z to a about z x a = (-a.y, a.x, 0).
  const Vec3 k(-a.y, a.x, 0.f);
  const float sin_t = length(k);
  const Mat3 swing = sin_t > 1e-7f ? rotation_axis_angle(k / sin_t, atan2f(sin_t, a.z)) : Mat3::identity();
  const Mat3 roll = rotation_axis_angle(a, twist_deg * kDegToRad);
  return roll * swing;
}

BrushPose pose_from_pen(const PenSample& s, float elevation, const BrushSpec& brush) {
  BrushPose pose;
  pose.rotation = brush_rotation(s.tilt_x, s.tilt_y, s.twist);
  const Vec3 axis = pose.rotation.col(2);
  pose.position = Vec3(s.x, s.y, 0.f) + axis * handle_distance(elevation, brush);
  return pose;
}

BrushPose pose_from_pen(const PenSample& s, const BrushSpec& brush) {
  return pose_from_pen(s, pen_elevation(s), brush);
}

}  // namespace wb
