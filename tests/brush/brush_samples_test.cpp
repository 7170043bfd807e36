// Bristle samples (paper §4.1): Hermite spline through the vertices, Bishop frames
// (orthonormal, minimal twist, root frame attached to the handle), sample and frame
// velocities, and the rasterised bristle density psi (volume) and velocity.
#include <math.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "backend_fixture.h"
#include "core/brush/brush.h"
#include "core/brush/samples_kernels.h"
#include "core/exec/buffer.h"
#include "brush/brush_test_util.h"

namespace wb::test {

namespace {

enum Field { kX = 0, kT, kN, kB, kV, kOmega, kA, kAlpha };

class BrushSamplesTest : public BackendTest {};
}  // namespace

TEST(SampleKernels, RotationVectorInvertsRodrigues) {
  const Vec3 axes[] = {Vec3(1, 0, 0), normalize(Vec3(1, 2, 3)), normalize(Vec3(-0.3f, 0.1f, 0.9f))};
  for (const Vec3& a : axes)
    for (float angle : {0.f, 1e-5f, 1e-3f, 0.4f, 2.f, 3.1f, 3.14159f}) {
      const Vec3 w = brush::rotation_vector(rotation_axis_angle(a, angle));
      EXPECT_NEAR(w.x, a.x * angle, 2e-4f) << angle;
      EXPECT_NEAR(w.y, a.y * angle, 2e-4f) << angle;
      EXPECT_NEAR(w.z, a.z * angle, 2e-4f) << angle;
    }
}

TEST(SampleKernels, HermiteInterpolatesVerticesAndTangents) {
  const Vec3 p0(0, 0, 0), p1(3, 1, -2), m0(1, 0, 0), m1(0, 2, 0);
  Vec3 d;
  const Vec3 a = brush::hermite(p0, m0, p1, m1, 0.f, d);
  EXPECT_NEAR(length(a - p0), 0.f, 1e-6f);
  EXPECT_NEAR(length(d - m0), 0.f, 1e-6f);
  const Vec3 b = brush::hermite(p0, m0, p1, m1, 1.f, d);
  EXPECT_NEAR(length(b - p1), 0.f, 1e-6f);
  EXPECT_NEAR(length(d - m1), 0.f, 1e-6f);
}

TEST_F(BrushSamplesTest, BishopFramesAreOrthonormalAndMinimallyTwisted) {
  const BrushSpec spec = default_brush(BrushShape::Round);
  Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length), rot_z(35)));
  // Press and drag with a tilted, twisting handle so that bristles bend in 3D.
  for (int s = 1; s <= 30; ++s) {
    const float t = float(s) * kDt;
    brush.step(make_pose(Vec3(250 + 200 * t, 250 + 100 * t * t, spec.length * 0.65f), rot_z(35 + 60 * t) * rot_x(30)),
               kDt, BrushEnvironment{});
  }
  const auto f = brush.sample_fields_to_host();
  const int S = spec.samples_per_bristle;
  const Mat3 R = rot_z(35 + 60 * 30 * kDt) * rot_x(30);
  double max_ortho = 0, max_twist = 0, max_bend = 0;
  for (int k = 0; k < spec.bristles; ++k) {
    const size_t base = size_t(k) * S;
    // Root frame attached to the brush: n is the handle's x axis made normal to t.
    const Vec3 t0 = f[kT][base], ax = R.col(0);
    const Vec3 n_expect = normalize(ax - t0 * dot(t0, ax));
    EXPECT_NEAR(length(f[kN][base] - n_expect), 0.f, 1e-4f);
    for (int j = 0; j < S; ++j) {
      const size_t q = base + j;
      const Vec3 t = f[kT][q], n = f[kN][q], b = f[kB][q];
      for (double e : {std::fabs(length(t) - 1.0), std::fabs(length(n) - 1.0), std::fabs(length(b) - 1.0),
                       std::fabs(double(dot(t, n))), std::fabs(double(dot(t, b))), std::fabs(double(dot(n, b))),
                       double(length(cross(t, n) - b))})
        max_ortho = std::max(max_ortho, e);
      if (j == 0) continue;
      // n_j must be n_{j-1} carried by the rotation taking t_{j-1} to t_j: no twist about t_j.
      const Vec3 tp = f[kT][q - 1];
      const Vec3 carried = normalize(brush::parallel_transport(f[kN][q - 1], tp, t));
      const double twist = std::atan2(double(dot(cross(carried, n), t)), double(dot(carried, n)));
      max_twist = std::max(max_twist, std::fabs(twist));
      max_bend = std::max(max_bend, double(std::acos(std::min(1.f, dot(tp, t)))));
    }
  }
  EXPECT_LT(max_ortho, 1e-4);
  EXPECT_LT(max_twist, 1e-4);
  EXPECT_GT(max_bend, 0.05) << "the pressed bristles are bent, so the transport was exercised";
}

TEST_F(BrushSamplesTest, SampleGapBelowOneCell) {
  const BrushSpec spec = default_brush(BrushShape::Rigger);  // the longest preset
  Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length)));
  for (int s = 1; s <= 20; ++s)
    brush.step(make_pose(Vec3(250 + 5.f * s, 250, spec.length * 0.6f), rot_x(30)), kDt, BrushEnvironment{});
  const auto x = brush.samples_to_host();
  const int S = spec.samples_per_bristle;
  float worst = 0.f;
  for (int k = 0; k < spec.bristles; ++k)
    for (int j = 1; j < S; ++j) worst = std::max(worst, length(x[size_t(k) * S + j] - x[size_t(k) * S + j - 1]));
  EXPECT_LT(worst, 1.f);
}

TEST_F(BrushSamplesTest, RigidMotionGivesSampleVelocitiesAndFrameRotation) {
  BrushSpec spec = default_brush(BrushShape::Round);
  spec.beta_B = 0.f;
  BrushEnvironment env;
  env.gravity = Vec3();
  const Vec3 vel(600, -300, 0);
  const float spin = 2.f;  // rad/s about z
  Brush brush(device_, spec, make_pose(Vec3(250, 250, 200)));
  for (int s = 1; s <= 5; ++s) {
    const float t = float(s) * kDt;
    brush.step(make_pose(Vec3(250, 250, 200) + vel * t, rotation_axis_angle(Vec3(0, 0, 1), spin * t)), kDt, env);
  }
  const auto f = brush.sample_fields_to_host();
  const Vec3 centre = Vec3(250, 250, 200) + vel * (5 * kDt);
  double worst_v = 0, worst_w = 0, worst_a = 0, worst_alpha = 0;
  for (size_t q = 0; q < f[kX].size(); ++q) {
    // Rigid motion: v = V + w x r (finite difference over one step of a rotation by w dt).
    const Vec3 r = f[kX][q] - centre;
    const Vec3 v_expect = vel + cross(Vec3(0, 0, spin), r);
    worst_v = std::max(worst_v, double(length(f[kV][q] - v_expect)) / length(v_expect));
    worst_w = std::max(worst_w, double(length(f[kOmega][q] - Vec3(0, 0, spin))));
    worst_alpha = std::max(worst_alpha, double(length(f[kAlpha][q])));
    // Centripetal acceleration of the spin: |a| = w^2 |r_xy|.
    const double a_expect = spin * spin * std::sqrt(double(r.x * r.x + r.y * r.y));
    worst_a = std::max(worst_a, std::fabs(double(length(f[kA][q])) - a_expect));
  }
  EXPECT_LT(worst_v, 0.02);
  EXPECT_LT(worst_w, 0.01);
  EXPECT_LT(worst_alpha, 1.0);
  EXPECT_LT(worst_a, 5.0);
}

TEST_F(BrushSamplesTest, SampleMotionIsTheWholeStepsWhateverTheSubsteps) {
  // A brush accelerating along x (v = a t): the samples' v, a over a step are the step's own
  // (v dt = the step's displacement), not the last sub-step's, so 1 and 8 sub-steps agree and
  // Eq. 9's rewind x - v dt lands on the step's start.
  BrushSpec spec = default_brush(BrushShape::Round);
  spec.beta_B = 0.f;
  BrushEnvironment env;
  env.gravity = Vec3();
  const float acc = 6000.f;  // cells/s^2
  auto run = [&](int substeps) {
    Brush brush(device_, spec, make_pose(Vec3(250, 250, 200)));
    std::vector<BrushPose> poses(static_cast<size_t>(substeps), make_pose(Vec3(250, 250, 200)));
    std::vector<Vec3> start;
    for (int s = 1; s <= 6; ++s) {
      for (int k = 0; k < substeps; ++k) {
        const float t = (float(s - 1) + float(k + 1) / float(substeps)) * kDt;
        poses[size_t(k)] = make_pose(Vec3(250 + 0.5f * acc * t * t, 250, 200));
      }
      start = brush.samples_to_host();
      brush.step(poses.data(), substeps, kDt, env);
    }
    const auto f = brush.sample_fields_to_host();
    double rewind = 0;
    for (size_t q = 0; q < f[kX].size(); ++q) rewind = std::max(rewind, double(length(f[kX][q] - f[kV][q] * kDt - start[q])));
    return std::make_tuple(f, rewind);
  };
  const auto [one, rewind_one] = run(1);
  const auto [eight, rewind_eight] = run(8);
  EXPECT_LT(rewind_one, 1e-3);
  EXPECT_LT(rewind_eight, 1e-3) << "x - v dt is the sample at the step's start";
  double dv = 0, da = 0;
  for (size_t q = 0; q < one[kV].size(); ++q) {
    dv = std::max(dv, double(length(one[kV][q] - eight[kV][q])));
    da = std::max(da, double(length(one[kA][q] - eight[kA][q])));
  }
  // Over 6 steps the brush reaches 6 * 100 = 600 cells/s; its acceleration is 6000 cells/s^2.
  EXPECT_LT(dv, 0.01 * 600) << "sample velocity independent of the sub-step count";
  EXPECT_LT(da, 0.05 * acc) << "sample acceleration independent of the sub-step count";
}

TEST_F(BrushSamplesTest, RasterisedPsiHoldsTheBristleVolumeAndVelocity) {
  BrushSpec spec = default_brush(BrushShape::Round);
  spec.beta_B = 0.f;
  BrushEnvironment env;
  env.gravity = Vec3();
  Brush brush(device_, spec, make_pose(Vec3(64, 64, 125)));  // in the air: no canvas friction
  const Vec3 vel(300, 120, -60);
  for (int s = 1; s <= 3; ++s) brush.step(make_pose(Vec3(64, 64, 125) + vel * (s * kDt)), kDt, env);
  const Int3 origin{0, 0, 0}, dims{128, 128, 128};
  const size_t cells = size_t(dims.x) * dims.y * dims.z;
  DeviceBuffer<float> psi(device_, cells), vx(device_, cells), vy(device_, cells), vz(device_, cells);
  brush.rasterize(origin, dims, psi.data(), vx.data(), vy.data(), vz.data());
  const auto p = psi.to_host(), hx = vx.to_host(), hy = vy.to_host(), hz = vz.to_host();
  double volume = 0, expect = 0;
  float pmax = 0.f, worst_v = 0.f;
  for (size_t i = 0; i < cells; ++i) {
    volume += p[i];
    pmax = std::max(pmax, p[i]);
    if (p[i] > 1e-3f) worst_v = std::max(worst_v, length(Vec3(hx[i], hy[i], hz[i]) - vel));
  }
  const float r = spec.bristle_radius;
  for (float len : brush.layout().length) expect += M_PI * r * r * len;
  EXPECT_LE(pmax, 1.f);
  EXPECT_NEAR(volume, expect, 0.02 * expect) << "psi integrates to the bristles' volume";
  EXPECT_LT(worst_v, 1.f) << "a rigidly translating brush rasterises its own velocity";

  // A window elsewhere sees nothing; a window cutting the brush sees part of it.
  brush.rasterize(Int3{300, 300, 0}, Int3{32, 32, 32}, psi.data(), vx.data(), vy.data(), vz.data());
  double far = 0;
  const auto pf = psi.to_host();
  for (size_t i = 0; i < size_t(32 * 32 * 32); ++i) far += pf[i];
  EXPECT_EQ(far, 0.0);
}

}  // namespace wb::test
