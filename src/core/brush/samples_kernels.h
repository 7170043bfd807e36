// Bristle samples (paper §4.1 "Bristle samples and local frames"): the cubic Hermite
// spline through each bristle's vertices with finite-difference tangents, minimal-twist
// (Bishop) frames by discrete parallel transport (Bishop 1975; Bergou et al. 2008), the
// frames' angular velocity for Eq. 9, and the weights that rasterise samples into the
// bristle density psi of the window (boundary condition of the projection, Eq. 12).
#pragma once
#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb::brush {

/// Finite-difference tangent of vertex i of a polyline with n vertices (central inside,
/// one-sided at the ends), the Hermite tangent of the paper.
WB_HD WB_INLINE Vec3 fd_tangent(const Vec3* v, int i, int n) {
  if (i == 0) return v[1] - v[0];
  if (i == n - 1) return v[n - 1] - v[n - 2];
  return (v[i + 1] - v[i - 1]) * 0.5f;
}

/// Cubic Hermite spline on [p0, p1] with tangents m0, m1 at u in [0, 1]:
/// p(u) = h00 p0 + h10 m0 + h01 p1 + h11 m1; dp/du returned in `d`.
WB_HD WB_INLINE Vec3 hermite(Vec3 p0, Vec3 m0, Vec3 p1, Vec3 m1, float u, Vec3& d) {
  const float u2 = u * u, u3 = u2 * u;
  const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
  const float d00 = 6 * u2 - 6 * u, d10 = 3 * u2 - 4 * u + 1, d01 = -6 * u2 + 6 * u, d11 = 3 * u2 - 2 * u;
  d = p0 * d00 + m0 * d10 + p1 * d01 + m1 * d11;
  return p0 * h00 + m0 * h10 + p1 * h01 + m1 * h11;
}

/// Discrete parallel transport (Bergou et al. 2008): rotates n by the minimal rotation
/// taking unit t0 to unit t1, about t0 x t1 by the angle between them (Rodrigues).
WB_HD WB_INLINE Vec3 parallel_transport(Vec3 n, Vec3 t0, Vec3 t1) {
  const Vec3 axis = cross(t0, t1);
  const float s = length(axis), c = dot(t0, t1);
  if (s < 1e-8f) return n;  // parallel (or, degenerate, antiparallel): no unique rotation
  const Vec3 k = axis / s;
  return n * c + cross(k, n) * s + k * (dot(k, n) * (1.f - c));
}

/// A unit quaternion (w, v) as the frames' scan composes them.
struct Quat {
  float w;
  Vec3 v;
};
/// a b: the rotation b, then a.
WB_HD WB_INLINE Quat quat_mul(Quat a, Quat b) {
  return {a.w * b.w - dot(a.v, b.v), b.v * a.w + a.v * b.w + cross(a.v, b.v)};
}
WB_HD WB_INLINE Quat quat_normalize(Quat q) {
  const float l = sqrtf(q.w * q.w + dot(q.v, q.v));
  return l > 0.f ? Quat{q.w / l, q.v / l} : Quat{1.f, Vec3()};
}
WB_HD WB_INLINE Vec3 quat_rotate(Quat q, Vec3 n) {
  const Vec3 c = cross(q.v, n);
  return n + c * (2.f * q.w) + cross(q.v, c) * 2.f;
}
/// The minimal rotation taking unit t0 to unit t1 (parallel_transport's), as a quaternion:
/// (1 + t0.t1, t0 x t1) normalised; the identity where the two are parallel or opposite.
WB_HD WB_INLINE Quat transport_quat(Vec3 t0, Vec3 t1) {
  const Vec3 axis = cross(t0, t1);
  if (length(axis) < 1e-8f) return {1.f, Vec3()};
  return quat_normalize({1.f + dot(t0, t1), axis});
}

/// Rotation vector (axis * angle, angle in [0, pi]) of a rotation matrix; robust near 0
/// (first order from the skew part) and near pi (axis from the diagonal).
WB_HD WB_INLINE Vec3 rotation_vector(const Mat3& R) {
  const Vec3 w(R.r[2].y - R.r[1].z, R.r[0].z - R.r[2].x, R.r[1].x - R.r[0].y);  // 2 sin(a) axis
  const float c = clampf(0.5f * (R.r[0].x + R.r[1].y + R.r[2].z - 1.f), -1.f, 1.f);
  const float s2 = length(w);  // 2 sin(a)
  const float angle = atan2f(0.5f * s2, c);
  if (angle < 1e-4f) return w * 0.5f;
  if (angle < 3.1415926f - 1e-2f) return w * (angle / s2);
  // Near pi: R + R^T = 2 (c I + (1 - c) a a^T); take the largest diagonal for accuracy.
  int i = 0;
  if (R.r[1].y > R.r[i][i]) i = 1;
  if (R.r[2].z > R.r[i][i]) i = 2;
  const float one_c = 1.f - c;
  Vec3 a;
  const float ai = sqrtf(maxf((R.r[i][i] - c) / one_c, 0.f));
  for (int j = 0; j < 3; ++j) a[j] = j == i ? ai : (R.r[i][j] + R.r[j][i]) / (2.f * one_c * maxf(ai, 1e-12f));
  a = normalize_or(a, Vec3(1, 0, 0));
  if (dot(a, w) < 0.f) a = -a;
  return a * angle;
}

/// Volume a sample stands for: a cylinder of radius r along half the gaps to its two
/// neighbours (cells^3). Summed over a bristle it is pi r^2 times its length.
WB_HD WB_INLINE float sample_volume(float radius, float gap_prev, float gap_next) {
  return 3.14159265f * radius * radius * 0.5f * (gap_prev + gap_next);
}

}  // namespace wb::brush
