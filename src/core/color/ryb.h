// Colour (paper §6 "Color mixing model", Algorithm 2; DESIGN.md "Colour"). Pigment is an
// RYB vector in [0,1]^3 (0 = no pigment = white); display colour comes from the trilinear
// RYB cube of Gossett & Chen 2004. Mixing is linear in RYB, then the amount of pigment is
// rescaled so that the RGB brightness ||x||_M is the weighted mean of the inputs'.
// All functions are WB_HD: the transfer kernels mix colours, the renderer converts them.
#pragma once
#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// RGB of the eight corners of the RYB cube, index = r + 2 y + 4 b (Gossett & Chen 2004).
WB_HD WB_INLINE Vec3 ryb_corner(int i) {
  switch (i) {
    case 0: return Vec3(1.f, 1.f, 1.f);          // no pigment: white
    case 1: return Vec3(1.f, 0.f, 0.f);          // red
    case 2: return Vec3(1.f, 1.f, 0.f);          // yellow
    case 3: return Vec3(1.f, 0.5f, 0.f);         // red + yellow: orange
    case 4: return Vec3(0.163f, 0.373f, 0.6f);   // blue
    case 5: return Vec3(0.5f, 0.f, 0.5f);        // red + blue: purple
    case 6: return Vec3(0.f, 0.66f, 0.2f);       // yellow + blue: green
    default: return Vec3(0.2f, 0.094f, 0.f);     // all three: black (brownish)
  }
}

/// RYB -> RGB: trilinear interpolation of the corner colours; input clamped to [0,1]^3.
WB_HD WB_INLINE Vec3 ryb_to_rgb(Vec3 ryb) {
  const float r = clampf(ryb.x, 0.f, 1.f), y = clampf(ryb.y, 0.f, 1.f), b = clampf(ryb.z, 0.f, 1.f);
  const Vec3 c00 = lerp(ryb_corner(0), ryb_corner(1), r);
  const Vec3 c10 = lerp(ryb_corner(2), ryb_corner(3), r);
  const Vec3 c01 = lerp(ryb_corner(4), ryb_corner(5), r);
  const Vec3 c11 = lerp(ryb_corner(6), ryb_corner(7), r);
  return lerp(lerp(c00, c10, y), lerp(c01, c11, y), b);
}

/// Jacobian of ryb_to_rgb at ryb (columns d/dr, d/dy, d/db), for the inverse solve.
WB_HD WB_INLINE Mat3 ryb_to_rgb_jacobian(Vec3 ryb) {
  const float r = ryb.x, y = ryb.y, b = ryb.z;
  Vec3 k[8];
  for (int i = 0; i < 8; ++i) k[i] = ryb_corner(i);
  // f = sum_i w_i(r,y,b) k_i with w_i a product of (1-t) or t per axis.
  const Vec3 dr = ((k[1] - k[0]) * ((1 - y) * (1 - b)) + (k[3] - k[2]) * (y * (1 - b)) +
                   (k[5] - k[4]) * ((1 - y) * b) + (k[7] - k[6]) * (y * b));
  const Vec3 dy = ((k[2] - k[0]) * ((1 - r) * (1 - b)) + (k[3] - k[1]) * (r * (1 - b)) +
                   (k[6] - k[4]) * ((1 - r) * b) + (k[7] - k[5]) * (r * b));
  const Vec3 db = ((k[4] - k[0]) * ((1 - r) * (1 - y)) + (k[5] - k[1]) * (r * (1 - y)) +
                   (k[6] - k[2]) * ((1 - r) * y) + (k[7] - k[3]) * (r * y));
  return Mat3::from_columns(dr, dy, db);
}

/// Perceived brightness ||x||_M = sqrt(x^T M x), M = diag(0.241, 0.691, 0.068) (§6).
WB_HD WB_INLINE float brightness(Vec3 rgb) {
  return sqrtf(0.241f * rgb.x * rgb.x + 0.691f * rgb.y * rgb.y + 0.068f * rgb.z * rgb.z);
}

/// Brightness of a pigment vector: ||RYBtoRGB(c)||_M.
WB_HD WB_INLINE float pigment_brightness(Vec3 ryb) { return brightness(ryb_to_rgb(ryb)); }

/// The brightness rescale of Algorithm 2: returns s c with ||RYBtoRGB(s c)||_M = target.
/// In the RYB cube 0 is white, so the literal b''/b' factor would move brightness the wrong
/// way; the factor s is instead solved for on [0, 1/max(c)] (regula falsi, Illinois variant).
/// Clamp: when the target is darker than s = 1/max(c) can reach, s = 1/max(c), which keeps
/// the result in [0,1]^3. A zero vector (pure white) is returned unchanged (guards b' = 0).
WB_HD WB_INLINE Vec3 rescale_to_brightness(Vec3 c, float target) {
  const float cmax = maxf(c.x, maxf(c.y, c.z));
  if (!(cmax > 1e-7f)) return c;
  const float b1 = pigment_brightness(c);
  if (fabsf(b1 - target) < 1e-6f) return c;
  float lo = 0.f, hi = 1.f / cmax;
  float flo = 1.f - target;  // s = 0 is white, brightness 1
  float fhi = pigment_brightness(c * hi) - target;
  if (fhi >= 0.f) return c * hi;  // cannot get this dark inside the gamut: clamp
  if (flo <= 0.f) return c * 0.f;  // target at or above white
  int side = 0;
  float s = 1.f;
  for (int it = 0; it < 40; ++it) {
    s = (lo * fhi - hi * flo) / (fhi - flo);
    const float fs = pigment_brightness(c * s) - target;
    if (fabsf(fs) < 2e-6f || hi - lo < 1e-7f) break;
    if ((fs > 0.f) == (flo > 0.f)) {
      lo = s;
      flo = fs;
      if (side == -1) fhi *= 0.5f;
      side = -1;
    } else {
      hi = s;
      fhi = fs;
      if (side == 1) flo *= 0.5f;
      side = 1;
    }
  }
  return c * s;
}

/// Algorithm 2, Color_Mix(c_i, c_j, w_i, w_j): c' = (w_i c_i + w_j c_j)/(w_i + w_j), then
/// c' rescaled so that its brightness is b'' = (w_i b_i + w_j b_j)/(w_i + w_j). Weights <= 0
/// in total return c_i.
WB_HD WB_INLINE Vec3 color_mix(Vec3 ci, Vec3 cj, float wi, float wj) {
  const float ws = wi + wj;
  if (!(ws > 0.f)) return ci;
  const Vec3 c1 = (ci * wi + cj * wj) / ws;
  const float b2 = (wi * pigment_brightness(ci) + wj * pigment_brightness(cj)) / ws;
  return rescale_to_brightness(c1, b2);
}

/// Many-colour Color_Mix: linear RYB mix by weights w, rescaled to the weighted mean brightness.
WB_HD WB_INLINE Vec3 color_mix_n(const Vec3* c, const float* w, int n) {
  Vec3 sum(0.f, 0.f, 0.f);
  float ws = 0.f, bs = 0.f;
  for (int i = 0; i < n; ++i) {
    if (!(w[i] > 0.f)) continue;
    sum += c[i] * w[i];
    bs += w[i] * pigment_brightness(c[i]);
    ws += w[i];
  }
  if (!(ws > 0.f)) return Vec3(0.f, 0.f, 0.f);
  return rescale_to_brightness(sum / ws, bs / ws);
}

/// Inverse of ryb_to_rgb for picking colours: damped Gauss-Newton on ||RYBtoRGB(c) - rgb||^2,
/// projected onto [0,1]^3, started from the cube centre and the two achromatic ends. Inside the
/// gamut it returns the pigment whose colour is rgb; outside it, the nearest one it finds.
WB_HD WB_INLINE Vec3 rgb_to_ryb(Vec3 rgb) {
  const Vec3 seeds[3] = {Vec3(0.5f, 0.5f, 0.5f), Vec3(0.1f, 0.1f, 0.1f), Vec3(0.8f, 0.8f, 0.8f)};
  Vec3 best = seeds[0];
  float best_err = 1e30f;
  for (int s = 0; s < 3; ++s) {
    Vec3 c = seeds[s];
    float lambda = 1e-3f;
    Vec3 f = ryb_to_rgb(c) - rgb;
    float err = dot(f, f);
    for (int it = 0; it < 40 && err > 1e-12f; ++it) {
      const Mat3 J = ryb_to_rgb_jacobian(c);
      const Mat3 Jt = transpose(J);
      Mat3 A = Jt * J;
      for (int k = 0; k < 3; ++k) A.r[k][k] += lambda * (1.f + A.r[k][k]);
      const Vec3 g = Jt * f;
      // Solve A d = -g by Cramer's rule (A is 3x3 symmetric positive definite).
      const float det = dot(A.r[0], cross(A.r[1], A.r[2]));
      if (!(fabsf(det) > 1e-20f)) break;
      const Vec3 ng = -g;
      const Mat3 Ax = Mat3::from_columns(ng, A.col(1), A.col(2));
      const Mat3 Ay = Mat3::from_columns(A.col(0), ng, A.col(2));
      const Mat3 Az = Mat3::from_columns(A.col(0), A.col(1), ng);
      const Vec3 d(dot(Ax.r[0], cross(Ax.r[1], Ax.r[2])) / det, dot(Ay.r[0], cross(Ay.r[1], Ay.r[2])) / det,
                   dot(Az.r[0], cross(Az.r[1], Az.r[2])) / det);
      const Vec3 cn(clampf(c.x + d.x, 0.f, 1.f), clampf(c.y + d.y, 0.f, 1.f), clampf(c.z + d.z, 0.f, 1.f));
      const Vec3 fn = ryb_to_rgb(cn) - rgb;
      const float en = dot(fn, fn);
      if (en < err) {
        c = cn;
        f = fn;
        err = en;
        lambda = maxf(lambda * 0.3f, 1e-7f);
      } else {
        lambda *= 10.f;
        if (lambda > 1e6f) break;
      }
    }
    if (err < best_err) {
      best_err = err;
      best = c;
    }
  }
  return best;
}

}  // namespace wb
