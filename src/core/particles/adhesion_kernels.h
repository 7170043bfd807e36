// Particle stage, per-particle physics (paper §4.3, Eq. 8-10): friction near the
// solid surface, the two-step adhesion update (local sample frame, Eq. 9, and
// canvas frame), and their blend by the distance to the bristles (Eq. 10).
// Plain WB_HD functions of values: no allocation, no backend.
#pragma once
#include <cstdint>

#include "core/brush/bristle_fields.h"
#include "core/exec/hd.h"
#include "core/math/vec.h"
#include "core/particles/particle_params.h"

namespace wb {

/// What the particles rest on: the canvas floor, optionally raised by a height map of dried
/// paint over a window of columns (absolute z of the dried top, canvas cells), and the surface of
/// the wet grid paint over the same columns.
struct SolidView {
  float floor_z = 0.f;
  const float* height = nullptr;   ///< nx * ny columns, index j * nx + i; nullptr: floor only
  const float* wet_top = nullptr;  ///< top of the wet paint per column (>= height); nullptr: none
  int nx = 0, ny = 0;
  int ox = 0, oy = 0;  ///< canvas cell of column (0, 0)
};

/// Height of the solid surface under p, canvas cells.
WB_HD WB_INLINE float solid_surface_z(const SolidView& s, Vec3 p) {
  float z = s.floor_z;
  if (s.height) {
    const int i = int(floorf(p.x)) - s.ox, j = int(floorf(p.y)) - s.oy;
    if (i >= 0 && j >= 0 && i < s.nx && j < s.ny) z = maxf(z, s.height[int64_t(j) * s.nx + i]);
  }
  return z;
}

/// Surface of the paint under p: the wet paint's free surface where there is wet paint, else
/// the solid's, canvas cells.
WB_HD WB_INLINE float paint_surface_z(const SolidView& s, Vec3 p) {
  float z = solid_surface_z(s, p);
  if (s.wet_top) {
    const int i = int(floorf(p.x)) - s.ox, j = int(floorf(p.y)) - s.oy;
    if (i >= 0 && j >= 0 && i < s.nx && j < s.ny) z = maxf(z, s.wet_top[int64_t(j) * s.nx + i]);
  }
  return z;
}

/// d_k of Eq. 8: distance from p to the solid surface below it (vertical: the solid is a
/// height field), cells, >= 0.
WB_HD WB_INLINE float solid_distance(const SolidView& s, Vec3 p) { return maxf(p.z - solid_surface_z(s, p), 0.f); }

/// Eq. 8 weight w = max(1 - delta d, 0)^2. The paper prints max((1 - delta d)^2, 0), which is
/// never clipped and would grow again beyond 1/delta; the range reading is the intended one.
WB_HD WB_INLINE float friction_weight(float d, float delta) {
  const float s = maxf(1.f - delta * d, 0.f);
  return s * s;
}

/// Eq. 8 over a step. The paper's f = -w v is a drag; read as a rate, dv/dt = -k w v with k the
/// friction rate at the surface (1/s), so the same paint slows the same whatever the step: exact
/// over the step, v ends at v e^{-k w dt} and moves on average (1 - e^{-k w dt}) / (k w dt) of v dt.
/// Reading it as "the velocity change of one step" (v (1 - w) a step) damped paint twice as much
/// in half the time at half the step, and missed a velocity gained within the step (a bristle's
/// jolt), which then carried paint lying on the canvas by (1 - beta_L) dV dt: half as far at
/// half the step (docs/PARTICLES.md "Friction as a rate").
struct FrictionDecay {
  float mean = 1.f;  ///< mean velocity over the step / starting velocity
  float end = 1.f;   ///< velocity at the end of the step / starting velocity
};
WB_HD WB_INLINE FrictionDecay friction_decay(float d, float delta, float rate, float dt) {
  const float x = rate * friction_weight(d, delta) * dt;
  if (x < 1e-6f) return FrictionDecay{};
  // (1 - e^-x) / x from e^-x alone (one expf, not expm1f as well: 3 % of a step's CPU time);
  // below x = 0.01, where 1 - e^-x would lose digits, its series (the next term x^4 / 120).
  const float end = expf(-x);
  const float mean = x < 1e-2f ? 1.f - x * (0.5f - x * (1.f / 6.f - x * (1.f / 24.f))) : (1.f - end) / x;
  return FrictionDecay{mean, end};
}

/// Eq. 10 weight of the local-frame result: max(1 - d_B / D1, 0).
WB_HD WB_INLINE float adhesion_weight(float d_B, float D1) { return D1 > 0.f ? maxf(1.f - d_B / D1, 0.f) : 0.f; }

/// Eq. 10: p_new = p'' + max(1 - d_B/D1, 0) (p' - p'').
WB_HD WB_INLINE Vec3 adhesion_blend(Vec3 p_local, Vec3 p_canvas, float d_B, float D1) {
  return p_canvas + (p_local - p_canvas) * adhesion_weight(d_B, D1);
}

/// One bristle sample's frame and motion, canvas frame (see bristle_fields.h).
struct SampleFrame {
  Vec3 x, t, n, b, v, omega, a, alpha;
};

WB_HD WB_INLINE SampleFrame load_sample(const SampleView& s, int64_t j) {
  return SampleFrame{s.x[j], s.t[j], s.n[j], s.b[j], s.v[j], s.omega[j], s.a[j], s.alpha[j]};
}

/// R v with R's rows t, n, b: canvas -> local coordinates.
WB_HD WB_INLINE Vec3 to_local(Vec3 t, Vec3 n, Vec3 b, Vec3 v) { return Vec3(dot(t, v), dot(n, v), dot(b, v)); }
/// R^T v: local -> canvas coordinates.
WB_HD WB_INLINE Vec3 to_canvas(Vec3 t, Vec3 n, Vec3 b, Vec3 v) { return t * v.x + n * v.y + b * v.z; }

/// The canvas-frame update without adhesion (symplectic Euler): p'' = p + dt (v + dt a_k).
WB_HD WB_INLINE Vec3 canvas_frame_step(Vec3 p, Vec3 v, Vec3 a_k, float dt) { return p + (v + a_k * dt) * dt; }

/// The part of a sample frame's rotation that paint around the bristle feels. A bristle is
/// round: its Bishop frame's spin about the tangent t is a by-product of parallel transport
/// along the moving curve, not a motion of the fibre, and at sharp bends it reached 2500 rad/s
/// on a 16-cell brush, flinging particles up to D1 away around the bristle. Only the rotation
/// that turns t is kept (omega - (omega . t) t, likewise alpha).
WB_HD WB_INLINE SampleFrame physical_rotation(SampleFrame s) {
  s.omega = s.omega - s.t * dot(s.omega, s.t);
  s.alpha = s.alpha - s.t * dot(s.alpha, s.t);
  return s;
}

/// A sample's part of Eq. 9, the same for every particle it holds (worked out once a sample a
/// step: sample_motion). The sample holds its state at the end of the brush step (t + dt), with
/// velocities from position differences (v = dx/dt, a = dv/dt, rotation over the step = omega dt,
/// as position-based dynamics produces them). The frame at t is therefore x - v dt, axes rotated
/// by -omega dt, velocity v - a dt, angular velocity omega - alpha dt.
struct SampleMotion {
  Vec3 x0, v0, w0;  ///< the frame's origin, velocity and angular velocity at t (canvas)
  Vec3 t0, n0, b0;  ///< its axes at t: R_L's rows
  Vec3 W, Wdot, A;  ///< R_L omega_j, R_L alpha_j, R_L a_j
  Vec3 x, t, n, b;  ///< the frame at t + dt, where p^l maps back
};

WB_HD WB_INLINE SampleMotion sample_motion(const SampleFrame& s_in, float dt) {
  const SampleFrame s = physical_rotation(s_in);
  SampleMotion m;
  m.x0 = s.x - s.v * dt;
  m.v0 = s.v - s.a * dt;
  m.w0 = s.omega - s.alpha * dt;
  m.t0 = s.t, m.n0 = s.n, m.b0 = s.b;
  const float wl = length(s.omega);
  if (wl * dt > 1e-7f) {
    const Vec3 axis = s.omega / wl;
    m.t0 = rotate_axis_angle(s.t, axis, -wl * dt);
    m.n0 = rotate_axis_angle(s.n, axis, -wl * dt);
    m.b0 = rotate_axis_angle(s.b, axis, -wl * dt);
  }
  m.W = to_local(m.t0, m.n0, m.b0, m.w0);
  m.Wdot = to_local(m.t0, m.n0, m.b0, s.alpha);
  m.A = to_local(m.t0, m.n0, m.b0, s.a);
  m.x = s.x, m.t = s.t, m.n = s.n, m.b = s.b;
  return m;
}

/// Eq. 9, the local-frame update; returns p' in the canvas frame. In the sample's frame at t:
///   p^l = R_L (p - x_j),  v^l = R_L (v_k - v_j - omega_j x (p - x_j)),
///   dv^l/dt = R_L a_k - beta_L (R_L a_j + w x (w x p^l) + R_L alpha_j x p^l + 2 w x v^l),  w = R_L omega_j,
/// integrated by symplectic Euler, and p^l mapped back with the frame at t + dt.
/// With beta_L = 0 and a_k = 0 a particle moving with the sample stays rigidly attached.
WB_HD WB_INLINE Vec3 local_frame_step(Vec3 p, Vec3 v, Vec3 a_k, const SampleMotion& m, float beta_L, float dt) {
  const Vec3 r = p - m.x0;
  Vec3 pl = to_local(m.t0, m.n0, m.b0, r);
  Vec3 vl = to_local(m.t0, m.n0, m.b0, v - m.v0 - cross(m.w0, r));
  const Vec3 inertial = m.A + cross(m.W, cross(m.W, pl)) + cross(m.Wdot, pl) + cross(m.W, vl) * 2.f;
  const Vec3 acc = to_local(m.t0, m.n0, m.b0, a_k) - inertial * beta_L;
  vl += acc * dt;
  pl += vl * dt;
  return m.x + to_canvas(m.t, m.n, m.b, pl);
}

/// One particle's two-step update (§4.3): external acceleration a_k = g; p' from the nearest
/// sample's frame (Eq. 9, only when d_B < D1), p'' in the canvas frame; blend (Eq. 10); the
/// friction of Eq. 8 slows the step's motion relative to the canvas, a velocity the bristle gave
/// within the step included; keep it above the solid. `sample` (the nearest sample's motion) may
/// be null when no sample is near.
/// One gravity for grid and particles: a particle inside the wet paint is part of it, and the grid
/// gives that paint its weight and its support (§4.2 gravity with the hydrostatic part, resisted
/// by the yield stress), which FLIP hands to the particle (Eq. 11); so g enters a_k only above
/// the paint. There a free particle falls onto the wet surface and rests on it, as on the solid;
/// a bristle holding it (Eq. 10 weight > 0) can still press it into the wet paint.
WB_HD WB_INLINE void adhesion_update(Vec3& p, Vec3& v, const SampleMotion* sample, float d_B, const SolidView& solid,
                                     const ParticleParams& prm, float dt) {
  const float d = solid_distance(solid, p);
  const bool in_paint = p.z < paint_surface_z(solid, p);
  const Vec3 a_k = in_paint ? Vec3(0.f, 0.f, 0.f) : prm.gravity;
  const Vec3 p_canvas = canvas_frame_step(p, v, a_k, dt);
  const float w = adhesion_weight(d_B, prm.D1);
  const bool held = sample && w > 0.f;
  Vec3 p_new = p_canvas;
  if (held) p_new = p_canvas + (local_frame_step(p, v, a_k, *sample, prm.beta_L, dt) - p_canvas) * w;
  // Friction slows the whole step's motion relative to the canvas: what the particle carried into
  // the step, gravity's pull and what a bristle gave it within the step.
  const FrictionDecay f = friction_decay(d, prm.delta, prm.friction_rate, dt);
  p_new = p + (p_new - p) * f.mean;
  // The particle cannot enter the solid (the projection only sees the solid on the grid), and
  // a free one coming down from above lands on the wet paint's surface.
  const float zs = !in_paint && !held ? paint_surface_z(solid, p_new) : solid_surface_z(solid, p_new);
  if (p_new.z < zs) p_new.z = zs;
  v = (p_new - p) * (f.end / (f.mean * dt));
  p = p_new;
}

/// Fig. 8(a) baseline, not used by the simulator: adhesion as an explicit spring toward the
/// nearest sample's position at the start of the step, a = a_ext + k (x_j - p), symplectic
/// Euler. Stable only for k dt^2 < 4; it must be that stiff to hold a particle at speed.
WB_HD WB_INLINE void spring_adhesion_step(Vec3& p, Vec3& v, Vec3 target, Vec3 a_ext, float k, float dt) {
  v += (a_ext + (target - p) * k) * dt;
  p += v * dt;
}

}  // namespace wb
