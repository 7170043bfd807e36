// Small fixed-size vector and matrix types for WB_HD kernel code (both backends).
#pragma once
#include <math.h>  // the global isfinite/sqrtf used by WB_HD code on the host too

#include <cmath>

#include "core/exec/hd.h"

namespace wb {

struct Vec3 {
  float x = 0.f, y = 0.f, z = 0.f;
  WB_HD constexpr Vec3() = default;
  WB_HD constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  WB_HD constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  WB_HD float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

WB_HD WB_INLINE Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
WB_HD WB_INLINE Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
WB_HD WB_INLINE Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
WB_HD WB_INLINE Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
WB_HD WB_INLINE Vec3 operator*(float s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
// Each component divided: a weighted mean of paint divides by a weight that may be subnormal,
// whose reciprocal overflows (0 x inf = NaN where a component is 0).
WB_HD WB_INLINE Vec3 operator/(Vec3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
WB_HD WB_INLINE Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
WB_HD WB_INLINE Vec3& operator-=(Vec3& a, Vec3 b) { return a = a - b; }
WB_HD WB_INLINE Vec3& operator*=(Vec3& a, float s) { return a = a * s; }
WB_HD WB_INLINE Vec3 mul(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
WB_HD WB_INLINE float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
WB_HD WB_INLINE Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
WB_HD WB_INLINE float length2(Vec3 a) { return dot(a, a); }
WB_HD WB_INLINE float length(Vec3 a) { return sqrtf(dot(a, a)); }
/// Unit vector along a; `fallback` when a is (nearly) zero.
WB_HD WB_INLINE Vec3 normalize_or(Vec3 a, Vec3 fallback) {
  const float l = length(a);
  return l > 1e-12f ? a / l : fallback;
}
WB_HD WB_INLINE Vec3 normalize(Vec3 a) { return normalize_or(a, Vec3(0.f, 0.f, 1.f)); }
WB_HD WB_INLINE Vec3 lerp(Vec3 a, Vec3 b, float t) { return a + (b - a) * t; }
WB_HD WB_INLINE bool isfinite3(Vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
WB_HD WB_INLINE float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
WB_HD WB_INLINE int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }
WB_HD WB_INLINE float minf(float a, float b) { return a < b ? a : b; }
WB_HD WB_INLINE float maxf(float a, float b) { return a > b ? a : b; }
WB_HD WB_INLINE int imin(int a, int b) { return a < b ? a : b; }
WB_HD WB_INLINE int imax(int a, int b) { return a > b ? a : b; }
/// a + b and a - b rounded as written, never fused with the multiply that made an operand (nvcc
/// contracts x*y + z into one FMA): for sums two threads must round alike, such as a face's
/// flux given by one cell and taken by the other. The host build turns contraction off
/// (-ffp-contract=off in CMakeLists.txt).
WB_HD WB_INLINE float add_rn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fadd_rn(a, b);
#else
  return a + b;
#endif
}
WB_HD WB_INLINE float sub_rn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fsub_rn(a, b);
#else
  return a - b;
#endif
}

/// Row-major 3x3 matrix; rows r[0..2].
struct Mat3 {
  Vec3 r[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  WB_HD static Mat3 identity() { return Mat3(); }
  /// Matrix whose columns are a, b, c.
  WB_HD static Mat3 from_columns(Vec3 a, Vec3 b, Vec3 c) {
    Mat3 m;
    m.r[0] = Vec3(a.x, b.x, c.x);
    m.r[1] = Vec3(a.y, b.y, c.y);
    m.r[2] = Vec3(a.z, b.z, c.z);
    return m;
  }
  WB_HD Vec3 col(int i) const { return Vec3(r[0][i], r[1][i], r[2][i]); }
};
WB_HD WB_INLINE Vec3 operator*(const Mat3& m, Vec3 v) { return {dot(m.r[0], v), dot(m.r[1], v), dot(m.r[2], v)}; }
WB_HD WB_INLINE Mat3 transpose(const Mat3& m) { return Mat3::from_columns(m.r[0], m.r[1], m.r[2]); }
WB_HD WB_INLINE Mat3 operator*(const Mat3& a, const Mat3& b) {
  const Mat3 bt = transpose(b);
  Mat3 m;
  for (int i = 0; i < 3; ++i) m.r[i] = Vec3(dot(a.r[i], bt.r[0]), dot(a.r[i], bt.r[1]), dot(a.r[i], bt.r[2]));
  return m;
}

/// Rotation about a unit axis by angle (radians), Rodrigues' formula.
WB_HD WB_INLINE Mat3 rotation_axis_angle(Vec3 axis, float angle) {
  const float c = cosf(angle), s = sinf(angle), t = 1.f - c;
  const Vec3 a = axis;
  Mat3 m;
  m.r[0] = Vec3(t * a.x * a.x + c, t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y);
  m.r[1] = Vec3(t * a.x * a.y + s * a.z, t * a.y * a.y + c, t * a.y * a.z - s * a.x);
  m.r[2] = Vec3(t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c);
  return m;
}

/// Rotates v about unit axis by angle (Rodrigues), without building a matrix.
WB_HD WB_INLINE Vec3 rotate_axis_angle(Vec3 v, Vec3 axis, float angle) {
  const float c = cosf(angle), s = sinf(angle);
  return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1.f - c));
}

}  // namespace wb
