// The brush simulation (paper §4.1) as physical behaviour: inextensibility under an
// aggressive stroke, footprint growing with pressure, beta_B = 0 keeping the rest shape,
// the inertial terms of Eq. 2, anisotropic flat footprints, collisions with the canvas
// and dried paint, containment of non-finite input, the minimum-density constraint,
// drag from the paint flow and determinism.
#include <math.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "backend_fixture.h"
#include "core/brush/brush.h"
#include "core/brush/brush_kernels.h"
#include "core/canvas/tile_store.h"
#include "core/exec/buffer.h"
#include "brush/brush_test_util.h"

namespace wb::test {

namespace {

BrushEnvironment air() {
  BrushEnvironment env;
  env.gravity = Vec3();
  return env;
}

struct Footprint {
  int64_t count = 0;
  double mx = 0, my = 0, cxx = 0, cyy = 0, cxy = 0;
  int min_x = 1 << 30, max_x = -(1 << 30);
};

class BrushTest : public BackendTest {
 protected:
  static constexpr int kTrace = 512;

  Footprint footprint(Brush& brush, float contact_height = 1.f, const SolidField& solid = {}) {
    DeviceBuffer<int32_t> trace(device_, size_t(kTrace) * kTrace);
    trace.fill_zero();
    Footprint f;
    f.count = brush.mark_contacts(trace.data(), kTrace, kTrace, 0, 0, contact_height, solid);
    const auto t = trace.to_host();
    int64_t ones = 0;
    for (int y = 0; y < kTrace; ++y)
      for (int x = 0; x < kTrace; ++x)
        if (t[size_t(y) * kTrace + x]) {
          ++ones;
          f.mx += x;
          f.my += y;
          f.min_x = std::min(f.min_x, x);
          f.max_x = std::max(f.max_x, x);
        }
    EXPECT_EQ(ones, f.count) << "distinct contact count equals the cells marked on a fresh trace";
    if (ones == 0) return f;
    f.mx /= double(ones);
    f.my /= double(ones);
    for (int y = 0; y < kTrace; ++y)
      for (int x = 0; x < kTrace; ++x)
        if (t[size_t(y) * kTrace + x]) {
          f.cxx += (x - f.mx) * (x - f.mx);
          f.cyy += (y - f.my) * (y - f.my);
          f.cxy += (x - f.mx) * (y - f.my);
        }
    f.cxx /= double(ones);
    f.cyy /= double(ones);
    f.cxy /= double(ones);
    return f;
  }

  static float min_vertex_z(const std::vector<Vec3>& v) {
    float m = 1e30f;
    for (const Vec3& p : v) m = std::min(m, p.z);
    return m;
  }
  static bool all_finite(const std::vector<Vec3>& v) {
    for (const Vec3& p : v)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
    return true;
  }
};
}  // namespace

TEST_F(BrushTest, RestShapeAtConstruction) {
  const BrushSpec spec = default_brush(BrushShape::Round);
  const Vec3 p(200, 200, 150);
  Brush brush(device_, spec, make_pose(p));
  const auto xb = brush.vertices_brush_frame_to_host();
  const auto x = brush.vertices_to_host();
  ASSERT_EQ(xb.size(), brush.layout().rest.size());
  for (size_t i = 0; i < xb.size(); ++i) {
    EXPECT_EQ(xb[i].x, brush.layout().rest[i].x);
    EXPECT_NEAR(x[i].z, p.z + xb[i].z, 1e-4f);
  }
  const BrushStats st = brush.stats();
  EXPECT_LT(st.max_stretch, 1e-5f);
  EXPECT_EQ(st.nonfinite, 0);
  // Samples lie on the bristles: the first and last sample of a bristle are its root and tip.
  const auto s = brush.samples_to_host();
  const int S = spec.samples_per_bristle, V = spec.vertices_per_bristle;
  for (int k = 0; k < spec.bristles; k += 17) {
    EXPECT_NEAR(length(s[size_t(k) * S] - x[size_t(k) * V]), 0.f, 1e-3f);
    EXPECT_NEAR(length(s[size_t(k) * S + S - 1] - x[size_t(k) * V + V - 1]), 0.f, 1e-3f);
  }
}

// beta_B = 0 (paper §4.1): "Equation 2 forces the vertex to stay with the brush".
TEST_F(BrushTest, BetaZeroKeepsRestShapeUnderTranslationAndRotation) {
  BrushSpec spec = default_brush(BrushShape::Flat);
  spec.beta_B = 0.f;
  Brush brush(device_, spec, make_pose(Vec3(250, 250, 200)));
  const auto rest = brush.layout().rest;
  for (int s = 1; s <= 90; ++s) {
    const float t = float(s) * kDt;
    // Fast, accelerating, rotating motion through air, well above the canvas.
    const Vec3 p(250 + 120 * std::sin(7 * t), 250 + 80 * std::cos(5 * t), 200 + 30 * std::sin(11 * t));
    const Mat3 R = rot_z(200 * std::sin(3 * t)) * rot_x(40 * std::sin(4 * t));
    brush.step(make_pose(p, R), kDt, air());
  }
  const auto xb = brush.vertices_brush_frame_to_host();
  float worst = 0.f;
  for (size_t i = 0; i < xb.size(); ++i) worst = std::max(worst, length(xb[i] - rest[i]));
  EXPECT_LT(worst, 1e-4f);
}

TEST_F(BrushTest, BetaZeroTranslationMatchesAStillBrushUnderGravity) {
  BrushSpec spec = default_brush(BrushShape::Mop);  // soft: gravity visibly bends it when tilted
  spec.beta_B = 0.f;
  const Mat3 R = rot_x(60.f);
  Brush moving(device_, spec, make_pose(Vec3(250, 250, 300), R));
  Brush still(device_, spec, make_pose(Vec3(250, 250, 300), R));
  const BrushEnvironment env;  // gravity on
  for (int s = 1; s <= 40; ++s) {
    const float t = float(s) * kDt;
    moving.step(make_pose(Vec3(250 + 90 * std::sin(9 * t), 250 - 50 * t * t, 300), R), kDt, env);
    still.step(make_pose(Vec3(250, 250, 300), R), kDt, env);
  }
  const auto a = moving.vertices_brush_frame_to_host(), b = still.vertices_brush_frame_to_host();
  float worst = 0.f, sag = 0.f;
  for (size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, length(a[i] - b[i]));
    sag = std::max(sag, length(b[i] - moving.layout().rest[i]));
  }
  EXPECT_LT(worst, 1e-4f);
  EXPECT_GT(sag, 0.5f) << "gravity bends a tilted soft brush (else this test shows nothing)";
}

// Eq. 2 with beta_B > 0: the rectilinear term drags the bristles against the acceleration.
TEST_F(BrushTest, InertiaMakesBristlesLagBehindAnAcceleratingBrush) {
  BrushSpec spec = default_brush(BrushShape::Round);
  spec.beta_B = 0.1f;
  Brush brush(device_, spec, make_pose(Vec3(100, 250, 200)));
  // Constant acceleration along +x: 3e4 cells/s^2.
  const float acc = 3e4f;
  for (int s = 1; s <= 6; ++s) {
    const float t = float(s) * kDt;
    brush.step(make_pose(Vec3(100 + 0.5f * acc * t * t, 250, 200)), kDt, air());
  }
  const auto xb = brush.vertices_brush_frame_to_host();
  const int V = spec.vertices_per_bristle;
  double mean_dx = 0;
  for (int k = 0; k < spec.bristles; ++k)
    mean_dx += xb[size_t(k) * V + V - 1].x - brush.layout().rest[size_t(k) * V + V - 1].x;
  mean_dx /= spec.bristles;
  EXPECT_LT(mean_dx, -1.0) << "tips trail behind (-x) the brush accelerating along +x";
  EXPECT_LT(brush.stats().max_stretch, 0.01f);
}

TEST_F(BrushTest, SegmentsStayInextensibleInAnAggressivePressedZigZag) {
  for (BrushShape shape : {BrushShape::Round, BrushShape::Flat, BrushShape::Mop}) {
    BrushSpec spec = default_brush(shape);
    spec.beta_B = 0.1f;
    const float z = spec.length * 0.6f;  // pressed 40% of the length
    Brush brush(device_, spec, make_pose(Vec3(250, 250, z)));
    float worst = 0.f;
    for (int s = 1; s <= 120; ++s) {
      const float t = float(s) * kDt;
      // Zig-zag 60 cells wide at 4 Hz (~1000 cells/s), with a twisting handle.
      const float tri = 2.f * std::fabs(2.f * (4.f * t - std::floor(4.f * t + 0.5f))) - 1.f;
      brush.step(make_pose(Vec3(250 + 30 * tri, 180 + 150 * t, z), rot_z(30 * tri) * rot_x(15)), kDt, BrushEnvironment{});
      worst = std::max(worst, brush.stats().max_stretch);
    }
    EXPECT_LT(worst, 0.01f) << to_string(shape);
    EXPECT_EQ(brush.stats().nonfinite, 0);
  }
}

TEST_F(BrushTest, FootprintGrowsMonotonicallyWithPressure) {
  for (BrushShape shape : {BrushShape::Round, BrushShape::Flat}) {
    const BrushSpec spec = default_brush(shape);
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length * 1.2f)));
    int64_t last = 0;
    for (int level = 0; level <= 12; ++level) {
      const float press = 0.04f * float(level);  // up to 48% of the length
      const BrushPose pose = make_pose(Vec3(250, 250, spec.length * (1.05f - press)));
      for (int s = 0; s < 4; ++s) brush.step(pose, kDt, BrushEnvironment{});
      const int64_t area = footprint(brush).count;
      EXPECT_GE(area, last) << to_string(shape) << " at press " << press;
      last = area;
    }
    EXPECT_GT(last, 200) << to_string(shape) << ": a brush pressed by half its length leaves a footprint";
  }
}

TEST_F(BrushTest, FlatFootprintIsAlignedWithTheHandleWidthAxis) {
  const BrushSpec spec = default_brush(BrushShape::Flat);
  for (float angle : {0.f, 90.f}) {
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length), rot_z(angle)));
    const BrushPose pressed = make_pose(Vec3(250, 250, spec.length * 0.75f), rot_z(angle));
    for (int s = 0; s < 6; ++s) brush.step(pressed, kDt, BrushEnvironment{});
    const Footprint f = footprint(brush);
    ASSERT_GT(f.count, 50);
    // Major axis of the second moments.
    const double theta = 0.5 * std::atan2(2 * f.cxy, f.cxx - f.cyy) * 180.0 / M_PI;
    const double major = 0.5 * (f.cxx + f.cyy) + std::sqrt(0.25 * (f.cxx - f.cyy) * (f.cxx - f.cyy) + f.cxy * f.cxy);
    const double minor = 0.5 * (f.cxx + f.cyy) - std::sqrt(0.25 * (f.cxx - f.cyy) * (f.cxx - f.cyy) + f.cxy * f.cxy);
    EXPECT_GT(major, 3.0 * minor) << "anisotropic at " << angle;
    const double off = std::fabs(std::remainder(theta - angle, 180.0));
    EXPECT_LT(off, 10.0) << "major axis " << theta << " deg, handle width axis " << angle << " deg";
  }
}

TEST_F(BrushTest, FanSpreadsWiderThanRound) {
  auto pressed_width = [&](BrushShape shape) {
    const BrushSpec spec = default_brush(shape);
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length * 1.1f)));
    const BrushPose pressed = make_pose(Vec3(250, 250, spec.length * 0.7f));
    for (int s = 0; s < 6; ++s) brush.step(pressed, kDt, BrushEnvironment{});
    const Footprint f = footprint(brush);
    EXPECT_GT(f.count, 0) << to_string(shape);
    return f.max_x - f.min_x;
  };
  const int fan = pressed_width(BrushShape::Fan), round = pressed_width(BrushShape::Round);
  EXPECT_GT(fan, 2 * round) << "fan " << fan << " cells, round " << round;
}

TEST_F(BrushTest, NothingGoesBelowTheCanvasWhenPressedHard) {
  for (BrushShape shape : {BrushShape::Round, BrushShape::Flat, BrushShape::Mop, BrushShape::Rigger}) {
    const BrushSpec spec = default_brush(shape);
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length)));
    float lowest = 1e30f;
    for (int s = 1; s <= 60; ++s) {
      const float t = float(s) * kDt;
      const float z = spec.length * std::max(0.15f, 1.f - 3.f * t);  // down to 15% of the length
      brush.step(make_pose(Vec3(250 + 200 * t, 250 + 60 * std::sin(6 * t), z), rot_x(25 * std::sin(5 * t))), kDt,
                 BrushEnvironment{});
      lowest = std::min(lowest, brush.stats().min_z);
    }
    EXPECT_GE(lowest, -1e-4f) << to_string(shape);
    EXPECT_GE(min_vertex_z(brush.samples_to_host()), 0.f);
    EXPECT_LT(brush.stats().max_stretch, 0.01f) << to_string(shape);
  }
}

TEST_F(BrushTest, BristlesStayAboveADriedBlockOfPaint) {
  // Dried at once ("let it dry"), and by the canvas's drying clock, which the tiles have not
  // stored yet (the brush reads the dryness with the drying still owed).
  for (const bool by_clock : {false, true}) {
    SCOPED_TRACE(by_clock ? "dried by the clock" : "dry_all");
    TileStore canvas(device_, CanvasDims{512, 512, 64});
    // A dried block 40 x 40 cells, 12 cells high, under the brush.
    PaintWindow w(device_, Int3{64, 64, 32});
    w.set_origin({220, 220, 0});
    std::vector<std::vector<float>> f(kPaintFieldCount, std::vector<float>(size_t(w.cell_count()), 0.f));
    const int top = 12;
    for (int z = 0; z < top; ++z)
      for (int y = 10; y < 50; ++y)
        for (int x = 10; x < 50; ++x) f[0][size_t((z * 64 + y) * 64 + x)] = 1.f;
    w.from_host(f);
    canvas.scatter(w);
    if (by_clock)
      canvas.advance_drying(1.0);
    else
      canvas.dry_all();

    BrushEnvironment env;
    env.solid.tiles = canvas.view();
    env.solid.dryness_threshold = 0.9f;
    env.solid.valid = true;
    const BrushSpec spec = default_brush(BrushShape::Round);
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length + top + 5)));
    for (int s = 1; s <= 40; ++s) {
      const float z = spec.length * 0.65f + top;  // pressed 35% into the top of the block
      brush.step(make_pose(Vec3(250 + 0.2f * s, 250, z)), kDt, env);
    }
    int on_block = 0;
    for (const Vec3& p : brush.vertices_to_host()) {
      if (p.x >= 230 && p.x < 270 && p.y >= 230 && p.y < 270) {
        EXPECT_GE(p.z, float(top) - 1e-3f) << "vertex inside the dried block at " << p.x << "," << p.y << "," << p.z;
        ++on_block;
      }
    }
    EXPECT_GT(on_block, 100);
    for (const Vec3& p : brush.samples_to_host())
      if (p.x >= 230.5f && p.x < 269.5f && p.y >= 230.5f && p.y < 269.5f) ASSERT_GE(p.z, float(top) - 1e-3f);
    // The footprint is on top of the block: contact measured against the dried paint.
    const Footprint fp = footprint(brush, 1.f, env.solid);
    EXPECT_GT(fp.count, 100);
  }
}

TEST_F(BrushTest, HugeJumpsAndExtremeTiltStayFinite) {
  BrushSpec spec = default_brush(BrushShape::Round);
  spec.beta_B = 0.1f;
  Brush brush(device_, spec, make_pose(Vec3(300, 300, 70)));
  const Vec3 jumps[] = {Vec3(2300, 300, 70), Vec3(300, 2300, 70), Vec3(300, 300, 70), Vec3(2300, 2300, 40)};
  for (const Vec3& p : jumps) {
    brush.step(make_pose(p, rot_z(170)), kDt, BrushEnvironment{});
    brush.step(make_pose(p, rot_x(89)), kDt, BrushEnvironment{});
    brush.step(make_pose(p, rot_x(89) * rot_z(180)), kDt, BrushEnvironment{});
    brush.step(make_pose(p + Vec3(0, 0, -40), rot_x(-89)), kDt, BrushEnvironment{});
  }
  for (int s = 0; s < 20; ++s) brush.step(make_pose(Vec3(2300, 2300, 40), rot_x(89)), kDt, BrushEnvironment{});
  EXPECT_TRUE(all_finite(brush.vertices_to_host()));
  EXPECT_TRUE(all_finite(brush.samples_to_host()));
  for (const auto& field : brush.sample_fields_to_host()) EXPECT_TRUE(all_finite(field));
  const BrushStats st = brush.stats();
  EXPECT_EQ(st.nonfinite, 0);
  EXPECT_LT(st.max_stretch, 0.01f);
  EXPECT_GE(st.min_z, -1e-4f);
}

TEST_F(BrushTest, NonFiniteFlowIsContained) {
  const BrushSpec spec = default_brush(BrushShape::Round);
  Brush brush(device_, spec, make_pose(Vec3(32, 32, 60)));
  brush.step(make_pose(Vec3(32, 32, 60)), kDt, BrushEnvironment{});
  // A paint flow holding NaN and infinities: the drag term is non-finite for every vertex.
  const int n = 65 * 65 * 65;  // as many as any component's faces on 64^3 cells
  std::vector<float> bad(static_cast<size_t>(n)), ones(static_cast<size_t>(n), 1.f);
  for (int i = 0; i < n; ++i) bad[size_t(i)] = (i % 3 == 0) ? std::nanf("") : (i % 3 == 1 ? INFINITY : -INFINITY);
  DeviceBuffer<float> u(device_, size_t(n)), rho(device_, size_t(n));
  u.copy_from_host(bad);
  rho.copy_from_host(ones);
  DragField drag{u.data(), u.data(), u.data(), rho.data(), 64, 64, 64, 0, 0, 0, 10.f};
  BrushEnvironment env;
  env.drag = &drag;
  for (int s = 0; s < 5; ++s) {
    brush.step(make_pose(Vec3(33.f + s, 32, 60)), kDt, env);
    // Either the projections contained it within the step, or the step was rolled back.
    ASSERT_TRUE(all_finite(brush.vertices_to_host()));
    ASSERT_TRUE(all_finite(brush.vertices_brush_frame_to_host()));
    ASSERT_TRUE(all_finite(brush.vertex_velocities_to_host()));
    for (const auto& field : brush.sample_fields_to_host()) ASSERT_TRUE(all_finite(field));
    EXPECT_LT(brush.stats().max_stretch, 0.01f);
  }
  // The brush goes on normally afterwards.
  for (int s = 0; s < 5; ++s) brush.step(make_pose(Vec3(40, 32, 60)), kDt, BrushEnvironment{});
  EXPECT_TRUE(all_finite(brush.samples_to_host()));
  EXPECT_LT(brush.stats().max_stretch, 0.01f);
}

TEST_F(BrushTest, BadInputIsAnError) {
  const BrushSpec spec = default_brush(BrushShape::Round);
  Brush brush(device_, spec, make_pose(Vec3(32, 32, 60)));
  EXPECT_THROW(brush.step(make_pose(Vec3(32, 32, 60)), 0.f, BrushEnvironment{}), Error);
  EXPECT_THROW(brush.step(make_pose(Vec3(std::nanf(""), 32, 60)), kDt, BrushEnvironment{}), Error);
  Mat3 shear;
  shear.r[0] = Vec3(1, 0.5f, 0);
  EXPECT_THROW(brush.step(make_pose(Vec3(32, 32, 60), shear), kDt, BrushEnvironment{}), Error);
}

// Macklin & Müller 2013 style density bound: vertices of different bristles keep apart.
TEST_F(BrushTest, MinimumDensityKeepsBristlesApartWhenPressed) {
  struct Crowding {
    float s_min = 0.f;
    int64_t close_pairs = 0;  ///< pairs of vertices of different bristles closer than s_min / 2
    int64_t vertices = 0;
  };
  auto press = [&](int density_iterations, int substeps = 1) {
    BrushSpec spec = default_brush(BrushShape::Round);  // tapered: the tips crowd when pressed
    spec.bristles = 400;
    BrushSolverParams params;
    params.density_iterations = density_iterations;
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length)), params);
    auto pose = [&](float t) {
      return make_pose(Vec3(250 + 150 * t, 250, spec.length * std::max(0.55f, 1.f - 2.f * t)), rot_x(20));
    };
    std::vector<BrushPose> poses(static_cast<size_t>(substeps));
    for (int s = 1; s <= 30; ++s) {
      for (int k = 1; k <= substeps; ++k) poses[size_t(k - 1)] = pose((float(s - 1) + float(k) / float(substeps)) * kDt);
      brush.step(poses.data(), substeps, kDt, BrushEnvironment{});
    }
    Crowding c;
    c.s_min = brush.min_spacing();
    const auto x = brush.vertices_to_host();
    c.vertices = int64_t(x.size());
    const int V = spec.vertices_per_bristle;
    for (size_t i = 0; i < x.size(); ++i)
      for (size_t j = i + 1; j < x.size(); ++j)
        if (i / V != j / V && length(x[i] - x[j]) < 0.5f * c.s_min) ++c.close_pairs;
    EXPECT_LT(brush.stats().max_stretch, 0.01f) << "the density corrections keep the segment lengths";
    return c;
  };
  const Crowding with = press(4), without = press(0);
  EXPECT_GT(with.s_min, 0.2f);
  EXPECT_GT(without.close_pairs, 50) << "pressed tapered bristles crowd without the constraint";
  EXPECT_LT(with.close_pairs * 10, without.close_pairs) << with.close_pairs << " vs " << without.close_pairs;
  EXPECT_LT(double(with.close_pairs), 0.005 * double(with.vertices));
  // The same press in 8 sub-steps a step (the iterations run in each): the tips kept as far apart.
  const Crowding sub = press(4, 8), sub_without = press(0, 8);
  EXPECT_LT(sub.close_pairs * 10, sub_without.close_pairs) << sub.close_pairs << " vs " << sub_without.close_pairs;
  EXPECT_LT(double(sub.close_pairs), 0.005 * double(sub.vertices));
  std::printf("[ crowding ] pairs closer than s_min/2: %lld (4 iterations a step) vs %lld (none); in 8 sub-steps "
              "a step %lld vs %lld, of %d vertices\n",
              static_cast<long long>(with.close_pairs), static_cast<long long>(without.close_pairs),
              static_cast<long long>(sub.close_pairs), static_cast<long long>(sub_without.close_pairs),
              int(with.vertices));
}

TEST_F(BrushTest, DragFromThePaintFlowDeflectsTheBristles) {
  BrushSpec spec = default_brush(BrushShape::Round);
  spec.beta_B = 0.f;
  const int n = 128;
  const size_t cells = size_t(n + 1) * (n + 1) * 65;  // as many as any component's faces
  std::vector<float> ux(cells, 3000.f), zero(cells, 0.f), rho(cells, 1.f);
  DeviceBuffer<float> dux(device_, cells), dz(device_, cells), drho(device_, cells);
  dux.copy_from_host(ux);
  dz.copy_from_host(zero);
  drho.copy_from_host(rho);
  DragField drag{dux.data(), dz.data(), dz.data(), drho.data(), n, n, 64, 0, 0, 0, 20.f};
  BrushEnvironment env = air();
  env.drag = &drag;
  Brush brush(device_, spec, make_pose(Vec3(64, 64, 110)));
  for (int s = 0; s < 20; ++s) brush.step(make_pose(Vec3(64, 64, 110)), kDt, env);
  const auto xb = brush.vertices_brush_frame_to_host();
  const int V = spec.vertices_per_bristle;
  double dx = 0;
  for (int k = 0; k < spec.bristles; ++k) dx += xb[size_t(k) * V + V - 1].x - brush.layout().rest[size_t(k) * V + V - 1].x;
  dx /= spec.bristles;
  EXPECT_GT(dx, 1.0) << "tips pushed along +x by a +x flow";
  EXPECT_LT(brush.stats().max_stretch, 0.01f);
}

TEST_F(BrushTest, DeterministicOnRepeatedRuns) {
  auto run = [&]() {
    BrushSpec spec = default_brush(BrushShape::Filbert);
    Brush brush(device_, spec, make_pose(Vec3(250, 250, spec.length)));
    for (int s = 1; s <= 40; ++s) {
      const float t = float(s) * kDt;
      brush.step(make_pose(Vec3(250 + 300 * t, 250 + 40 * std::sin(8 * t), spec.length * 0.7f), rot_z(40 * t)), kDt,
                 BrushEnvironment{});
    }
    return brush.vertices_to_host();
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].x, b[i].x) << i;
    ASSERT_EQ(a[i].y, b[i].y) << i;
    ASSERT_EQ(a[i].z, b[i].z) << i;
  }
}

}  // namespace wb::test
