// Stroke input: pen to brush pose (docs/FORMATS.md "Pen to brush pose").
#include <gtest/gtest.h>

#include <cmath>

#include "core/io/pen_pose.h"

namespace wb {
namespace {

constexpr float kTol = 1e-4f;  // cells / unit vectors, float arithmetic on lengths ~100
constexpr float kPi = 3.14159265358979f;

PenSample pen(float x, float y, float p, float tx = 0, float ty = 0, float tw = 0, bool down = true) {
  PenSample s;
  s.x = x;
  s.y = y;
  s.pressure = p;
  s.tilt_x = tx;
  s.tilt_y = ty;
  s.twist = tw;
  s.down = down;
  return s;
}

void expect_vec(Vec3 a, Vec3 b, float tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

Vec3 rest_tip(const BrushPose& p, const BrushSpec& b) { return p.position - p.rotation.col(2) * b.length; }

TEST(PenPose, UprightTouchingIsIdentityWithTipsOnCanvas) {
  const BrushSpec b = default_brush(BrushShape::Round);
  const BrushPose p = pose_from_pen(pen(100, 50, 0), b);
  for (int i = 0; i < 3; ++i) expect_vec(p.rotation.col(i), Mat3::identity().col(i), 1e-6f);
  expect_vec(p.position, Vec3(100, 50, b.length));
  expect_vec(rest_tip(p, b), Vec3(100, 50, 0));
}

TEST(PenPose, PressureZeroTouchesAtAnyTilt) {
  const BrushSpec b = default_brush(BrushShape::Flat);
  for (float tx : {-60.f, -20.f, 0.f, 35.f})
    for (float ty : {-45.f, 0.f, 10.f, 70.f}) {
      const BrushPose p = pose_from_pen(pen(300, 200, 0, tx, ty, 40), b);
      expect_vec(rest_tip(p, b), Vec3(300, 200, 0));
    }
}

TEST(PenPose, FullPressureLowersByMaxPress) {
  BrushSpec b = default_brush(BrushShape::Round);
  b.max_press = 0.4f;
  const BrushPose p0 = pose_from_pen(pen(10, 10, 0), b);
  const BrushPose p1 = pose_from_pen(pen(10, 10, 1), b);
  const BrushPose ph = pose_from_pen(pen(10, 10, 0.5f), b);
  EXPECT_NEAR(p0.position.z - p1.position.z, 0.4f * b.length, kTol);
  EXPECT_NEAR(p0.position.z - ph.position.z, 0.2f * b.length, kTol);
  // Tilted: the drop is along the handle axis.
  const BrushPose t0 = pose_from_pen(pen(10, 10, 0, 30, 0), b);
  const BrushPose t1 = pose_from_pen(pen(10, 10, 1, 30, 0), b);
  EXPECT_NEAR(length(t0.position - t1.position), 0.4f * b.length, kTol);
}

TEST(PenPose, PenUpIsLiftedClear) {
  const BrushSpec b = default_brush(BrushShape::Round);
  const BrushPose up = pose_from_pen(pen(10, 10, 0.7f, 0, 0, 0, false), b);
  EXPECT_NEAR(up.position.z, b.length * (1.f + kPenUpLift), kTol);
  EXPECT_GT(rest_tip(up, b).z, 0.4f * b.length);
}

TEST(PenPose, TiltKeepsAxisThroughContactPoint) {
  const BrushSpec b = default_brush(BrushShape::Round);
  for (float p : {0.f, 0.3f, 1.f}) {
    const BrushPose pose = pose_from_pen(pen(500, 400, p, 40, -25, 77), b);
    const Vec3 axis = pose.rotation.col(2);
    const Vec3 from_contact = pose.position - Vec3(500, 400, 0);
    EXPECT_NEAR(length(cross(from_contact, axis)), 0.f, 1e-3f);
    EXPECT_GT(dot(from_contact, axis), 0.f);
  }
}

TEST(PenPose, TiltDirectionsFollowQtConvention) {
  // tilt_x alone rotates the handle about the canvas y axis toward +x.
  const float a = 30.f * kPi / 180.f;
  expect_vec(handle_axis(30, 0), Vec3(std::sin(a), 0, std::cos(a)), 1e-6f);
  expect_vec(handle_axis(0, 30), Vec3(0, std::sin(a), std::cos(a)), 1e-6f);
  const Vec3 d = handle_axis(-20, -20);
  EXPECT_NEAR(d.x, d.y, 1e-7f);
  EXPECT_LT(d.x, 0.f);
  // Projected angles: the x-z projection makes tilt_x with +z.
  const Vec3 e = handle_axis(25, 40);
  EXPECT_NEAR(std::atan2(e.x, e.z) * 180.f / kPi, 25.f, 1e-4f);
  EXPECT_NEAR(std::atan2(e.y, e.z) * 180.f / kPi, 40.f, 1e-4f);
}

TEST(PenPose, TiltClampedAt80Degrees) {
  const auto polar = [](Vec3 v) { return std::acos(v.z) * 180.f / kPi; };
  EXPECT_NEAR(polar(handle_axis(89, 0)), kMaxTiltDeg, 1e-3f);
  EXPECT_NEAR(polar(handle_axis(-120, 0)), kMaxTiltDeg, 1e-3f);
  // 78 and 78 degrees projected make 81.4 degrees from vertical.
  EXPECT_NEAR(polar(handle_axis(78, 78)), kMaxTiltDeg, 1e-3f);
  const Vec3 diag = handle_axis(78, 78);
  EXPECT_NEAR(diag.x, diag.y, 1e-6f);  // azimuth kept
  EXPECT_NEAR(polar(handle_axis(70, 70)), 75.56f, 0.01f);  // atan(sqrt(2) tan 70): not clamped
}

TEST(PenPose, TwistRollsBrushXAboutHandleAxis) {
  const BrushSpec b = default_brush(BrushShape::Flat);
  const BrushPose up = pose_from_pen(pen(0, 0, 0, 0, 0, 90), b);
  expect_vec(up.rotation.col(0), Vec3(0, 1, 0), 1e-6f);  // right-handed about +z
  for (float tw : {-170.f, 30.f, 123.f}) {
    const BrushPose p0 = pose_from_pen(pen(0, 0, 0.5f, 35, -20, 0), b);
    const BrushPose p1 = pose_from_pen(pen(0, 0, 0.5f, 35, -20, tw), b);
    const Vec3 axis = p0.rotation.col(2);
    expect_vec(p1.rotation.col(2), axis, 1e-6f);
    expect_vec(p1.position, p0.position);
    expect_vec(p1.rotation.col(0), rotate_axis_angle(p0.rotation.col(0), axis, tw * kPi / 180.f), 1e-5f);
  }
}

TEST(PenPose, RotationIsOrthonormal) {
  for (float tx = -85.f; tx <= 85.f; tx += 17.f)
    for (float ty = -85.f; ty <= 85.f; ty += 17.f)
      for (float tw = -360.f; tw <= 360.f; tw += 95.f) {
        const Mat3 r = brush_rotation(tx, ty, tw);
        const Mat3 rtr = transpose(r) * r;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) EXPECT_NEAR(rtr.r[i][j], i == j ? 1.f : 0.f, 1e-5f);
        EXPECT_NEAR(dot(cross(r.col(0), r.col(1)), r.col(2)), 1.f, 1e-5f);  // det = +1
      }
}

TEST(PenPose, HandleDistanceIsContinuousThroughContact) {
  const BrushSpec b = default_brush(BrushShape::Round);
  EXPECT_NEAR(handle_distance(-1e-6f, b), handle_distance(0.f, b), 1e-3f);
  EXPECT_NEAR(handle_distance(-1.f, b), b.length * (1.f + kPenUpLift), kTol);
  EXPECT_NEAR(handle_distance(1.f, b), b.length * (1.f - b.max_press), kTol);
  for (float e = -1.f; e < 1.f; e += 0.125f) EXPECT_GT(handle_distance(e, b), handle_distance(e + 0.125f, b));
}

}  // namespace
}  // namespace wb
