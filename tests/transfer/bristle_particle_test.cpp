// Bristle <-> particle transfer (paper §5.1, Eq. 12-14): capacity, absorption, colour
// bleeding and emission, checked as physical properties (mass conservation, bounds).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/color/ryb.h"
#include "core/particles/particle_params.h"
#include "transfer/transfer_fixture.h"

namespace wb::test {
namespace {
/// A window of 256 x 256 columns at the canvas's origin (swept_position keeps paint over it).
constexpr CellField kColumns{nullptr, 256, 256, 1, 0, 0, 0};

TEST(TransferCapacity, PotentialCapacityFallsWithPsiAndClampsAtMin) {
  const TransferParams p;
  float prev = potential_capacity(0.f, p.mu, p.M_max, p.M_min);
  EXPECT_FLOAT_EQ(prev, p.M_max);
  for (int i = 1; i <= 10; ++i) {
    const float psi = 0.1f * float(i);
    const float m = potential_capacity(psi, p.mu, p.M_max, p.M_min);
    EXPECT_LT(m, prev) << "psi " << psi;
    EXPECT_NEAR(m, (1.f - p.mu * psi) * p.M_max, 1e-6f * p.M_max);
    prev = m;
  }
  // mu = 1: a fully compressed sample would hold nothing; M_min holds.
  EXPECT_FLOAT_EQ(potential_capacity(1.f, 1.f, p.M_max, p.M_min), p.M_min);
  EXPECT_FLOAT_EQ(potential_capacity(0.9f, 1.f, p.M_max, p.M_min), p.M_min);
}

TEST(TransferSweep, SegmentAreaMatchesNumericIntegration) {
  // A(R, r) = area of the disc of radius R beyond the chord at distance r: 2 int_r^R sqrt(R^2 - z^2) dz.
  const float R = 0.75f;
  for (float r : {-0.5f, 0.f, 0.2f, 0.5f, 0.74f}) {
    double num = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const double z = r + (R - r) * (i + 0.5) / n;
      num += 2.0 * std::sqrt(std::max(double(R) * R - z * z, 0.0)) * (R - r) / n;
    }
    EXPECT_NEAR(segment_area(R, r), num, 1e-4) << "r " << r;
  }
  EXPECT_FLOAT_EQ(segment_area(R, R), 0.f);
  EXPECT_FLOAT_EQ(segment_area(R, 2.f), 0.f);
}

TEST(TransferSweep, DepositScalesWithDistanceSlidNotSteps) {
  const TransferParams p;
  const float cm = p.cell_mass(), m = p.M_max, split = 0.5f;
  // Proportional to the distance slid: one step of 4 cells leaves what two of 2 cells leave.
  const float one = swept_deposit(m, 0.f, 4.f, split, cm);
  const float half = swept_deposit(m, 0.f, 2.f, split, cm);
  EXPECT_NEAR(one, 2.f * half, 1e-6f * one);
  EXPECT_NEAR(one, split * cm * segment_area(load_radius(m, cm), 0.f) * 4.f, 1e-6f * one);
  // Not sliding, or not reaching the surface (a light load's sphere above it), leaves nothing.
  EXPECT_EQ(swept_deposit(m, 0.f, 0.f, split, cm), 0.f);
  EXPECT_EQ(swept_deposit(0.01f * m, 0.5f, 4.f, split, cm), 0.f) << "dry brush: the paint does not reach";
  EXPECT_GT(swept_deposit(m, 0.5f, 4.f, split, cm), 0.f);
  // The film under a full, pressed sample (R_m = R) balances where what it lays per cell slid
  // equals what it takes back of a film f: a pass takes film_pickup of a whole chord of each
  // particle in the band of 2 R it sweeps. split A(R, 0) = (1 - split) 2 R f at f = 0.59 cells.
  const float R = load_radius(m, cm), travel = 0.25f;
  const auto taken = [&](float f) { return film_pickup(split, 1.f) * 2.f * R * travel * f * cm; };
  const float balance = split * segment_area(R, 0.f) / ((1.f - split) * 2.f * R);
  EXPECT_NEAR(balance, 0.59f, 0.01f) << "a full, pressed sample lays 0.59 cells";
  const float laid = swept_deposit(m, 0.f, travel, split, cm);
  EXPECT_NEAR(taken(balance), laid, 1e-5f * laid);
  EXPECT_LT(taken(0.5f * balance), laid) << "a thinner film grows";
  EXPECT_GT(taken(2.f * balance), laid) << "a thicker one thins";
  // split = 0 is the paper's model: nothing leaves by sliding.
  EXPECT_EQ(swept_deposit(m, 0.f, 4.f, 0.f, cm), 0.f);
}

TEST(TransferSweep, ParticlesLayTheTrailAlongThePath) {
  float me = 0.f;
  // At most two particles per cell slid, each at most emit_mass.
  EXPECT_EQ(swept_count(1e-8f, 3.f, 1e-9f, me), 6);
  EXPECT_NEAR(me * 6.f, 1e-8f, 1e-14f);
  EXPECT_EQ(swept_count(2.5e-9f, 10.f, 1e-9f, me), 3);
  EXPECT_LE(me, 1e-9f);
  // Positions run from the step's start x - v dt to its end, above the surface.
  const Vec3 x(100.f, 50.f, 2.f), vt(600.f, 0.f, 0.f);
  const float dt = 1.f / 60.f;
  float lo = 1e9f, hi = -1e9f;
  for (int i = 0; i < 10; ++i) {
    const Vec3 q = swept_position(x, vt, dt, 0.5f, 1.5f, i, 10, 0.5f, emission_pattern_point(i, 16), 0.f, kColumns);
    lo = std::min(lo, q.x), hi = std::max(hi, q.x);
    EXPECT_NEAR(q.z, 2.f - 1.5f + 0.25f, 1e-5f);
  }
  EXPECT_LT(lo, x.x - 0.8f * 10.f);
  EXPECT_GT(hi, x.x - 0.2f * 10.f);
}

TEST(TransferSweep, OneParticleAStepLandsAnywhereAlongItsPath) {
  // A sample that leaves one particle a step puts it at a different point of each step's path,
  // uniformly over the path (a fixed point would print a bead every step).
  const Vec3 x(100.f, 50.f, 2.f), vt(300.f, 0.f, 0.f);
  const float dt = 1.f / 60.f;
  for (int64_t j : {0, 7, 4093}) {
    int bins[10] = {};
    for (int64_t step = 0; step < 2000; ++step) {
      const Vec3 q = swept_position(x, vt, dt, 0.f, 1.5f, 0, 1, step_uniform(j, step), Vec3(), 0.f, kColumns);
      const float u = (q.x - (x.x - vt.x * dt)) / (vt.x * dt);
      ASSERT_GE(u, 0.f);
      ASSERT_LT(u, 1.f);
      ++bins[int(u * 10.f)];
    }
    for (int b = 0; b < 10; ++b) EXPECT_NEAR(bins[b], 200, 50) << "sample " << j << ", tenth " << b << " of the path";
  }
}

TEST(TransferSweep, SamplesSweepingOneColumnShareTheirPassesDeposit) {
  // k passes in sequence, each closing `split` of the gap to the balance film: 1 - (1 - split)^k
  // of the gap in all, shared by the k samples of one step.
  for (float split : {0.25f, 0.5f, 0.9f}) {
    EXPECT_FLOAT_EQ(pass_share(1.f, split), 1.f) << "one pass keeps its deposit";
    for (int k : {2, 5, 40}) {
      double gap = 1.0;
      for (int i = 0; i < k; ++i) gap -= split * gap;
      EXPECT_NEAR(k * split * pass_share(float(k), split), 1.0 - gap, 1e-5) << k << " passes, split " << split;
      EXPECT_LT(pass_share(float(k), split), pass_share(float(k - 1), split));
    }
  }
  EXPECT_FLOAT_EQ(pass_share(4.f, 1.f), 0.25f) << "split 1: the first pass lays it all";
  EXPECT_FLOAT_EQ(pass_share(4.f, 0.f), 1.f);
  // The columns of a path: those of a point per cell slid, each once (5 cells: 5 or 6 columns).
  int n = 0;
  for_path_columns(Vec3(20.5f, 10.5f, 1.f), Vec3(300.f, 0.f, 0.f), 1.f / 60.f, 0, 0, 64, 64, [&](int ix, int iy) {
    EXPECT_EQ(iy, 10);
    EXPECT_GE(ix, 15);
    EXPECT_LE(ix, 20);
    ++n;
  });
  EXPECT_GE(n, 5);
  EXPECT_LE(n, 6);
}

TEST(TransferCapacity, CapFormulaMatchesNumericIntegration) {
  // The cap beyond a plane at distance r from the centre: integral_r^R pi (R^2 - z^2) dz.
  for (float R : {0.3f, 0.75f, 2.f}) {
    for (float f : {0.f, 0.1f, 0.37f, 0.5f, 0.8f, 1.f}) {
      const float r = f * R;
      const int n = 20000;
      double vol = 0;
      for (int i = 0; i < n; ++i) {
        const double z = r + (R - r) * (i + 0.5) / n;
        vol += M_PI * (double(R) * R - z * z) * (R - r) / n;
      }
      EXPECT_NEAR(spherical_cap_volume(R, R - r), vol, 1e-5 * R * R * R + 1e-4 * vol) << "R " << R << " r " << r;
    }
  }
  const TransferParams p;
  const float cm = p.cell_mass();
  const float R = load_radius(p.M_max, cm);
  // R is the radius of the sphere that holds M_max at rho0.
  EXPECT_NEAR(4.0 / 3.0 * M_PI * R * R * R * cm, p.M_max, 1e-5 * p.M_max);
  EXPECT_FLOAT_EQ(surface_capacity(p.M_max, R, R, cm), p.M_max);             // far: M = M'
  EXPECT_NEAR(surface_capacity(p.M_max, R, 0.f, cm), 0.5f * p.M_max, 1e-5f * p.M_max);  // touching: half
  EXPECT_NEAR(surface_capacity(p.M_max, R, -3.f, cm), 0.5f * p.M_max, 1e-5f * p.M_max);  // r clamped to 0
  EXPECT_FLOAT_EQ(surface_capacity(p.M_max, R, 5.f * R, cm), p.M_max);      // r clamped to R
}

TEST(TransferCapacity, BatchMixIsManyColourAlgorithm2) {
  const Vec3 c[4] = {Vec3(0.1f, 0.15f, 0.85f), Vec3(0.f, 0.9f, 0.f), Vec3(0.7f, 0.2f, 0.1f), Vec3(0.3f, 0.3f, 0.3f)};
  const float w[4] = {2.f, 0.5f, 1.f, 0.25f};
  Vec3 sum_c(0.f, 0.f, 0.f);
  float sum_b = 0.f, sum_w = 0.f;
  for (int i = 1; i < 4; ++i) {
    sum_c += c[i] * w[i];
    sum_b += w[i] * pigment_brightness(c[i]);
    sum_w += w[i];
  }
  const Vec3 a = mix_batch(c[0], w[0], sum_c, sum_b, sum_w);
  const Vec3 b = color_mix_n(c, w, 4);
  EXPECT_NEAR(a.x, b.x, 1e-5f);
  EXPECT_NEAR(a.y, b.y, 1e-5f);
  EXPECT_NEAR(a.z, b.z, 1e-5f);
  // Two colours: Algorithm 2 itself.
  const Vec3 two = mix_batch(c[0], w[0], c[1] * w[1], w[1] * pigment_brightness(c[1]), w[1]);
  const Vec3 ref = color_mix(c[0], c[1], w[0], w[1]);
  EXPECT_NEAR(two.x, ref.x, 1e-5f);
  EXPECT_NEAR(two.y, ref.y, 1e-5f);
  EXPECT_NEAR(two.z, ref.z, 1e-5f);
}

class BristleParticleTest : public TransferTest {};

TEST_F(BristleParticleTest, CapacityFarFromSurfacesAndUnderCompression) {
  HostSamples h = vertical_brush(2, 8, 0.8f, 16.f, 16.f, 20.f, 2.f);
  DeviceSamples s(device_);
  s.upload(h);
  const TransferParams prm;
  BristleLoad load(device_, s.view().count(), prm);
  PaintWindow w = make_window({32, 32, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  TransferEnv env = env_for(w);
  t.update_capacity(s.view(), load, env);
  BristleLoadHost lh = load.to_host();
  for (size_t j = 0; j < lh.m.size(); ++j) {
    EXPECT_FLOAT_EQ(lh.potential[j], prm.M_max);
    EXPECT_FLOAT_EQ(lh.capacity[j], prm.M_max) << "no surface within R: M = M'";
  }
  // A uniform psi = 0.6 over a window that holds the samples.
  PaintWindow tall = make_window({32, 32, 40}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  DeviceBuffer<float> psi(device_, size_t(tall.cell_count()));
  psi.copy_from_host(std::vector<float>(size_t(tall.cell_count()), 0.6f));
  TransferEnv env2 = env_for(tall);
  env2.psi = psi.data();
  t.update_capacity(s.view(), load, env2);
  lh = load.to_host();
  for (size_t j = 0; j < lh.m.size(); ++j) {
    EXPECT_NEAR(lh.potential[j], (1.f - 0.5f * 0.6f) * prm.M_max, 1e-6f * prm.M_max);
    EXPECT_NEAR(lh.radius[j], load_radius(lh.potential[j], prm.cell_mass()), 1e-5f);
  }
}

TEST_F(BristleParticleTest, CapacityFallsAsTheSampleApproachesTheFloor) {
  const TransferParams prm;
  const float R = load_radius(prm.M_max, prm.cell_mass());
  const float heights[] = {3.f, R, 0.75f * R, 0.5f * R, 0.25f * R, 0.f};
  const int n = int(std::size(heights));
  HostSamples h;
  h.resize(1, n);
  for (int j = 0; j < n; ++j) h.x[size_t(j)] = Vec3(10.f + 2.f * j, 10.f, heights[j]);
  DeviceSamples s(device_);
  s.upload(h);
  BristleLoad load(device_, n, prm);
  PaintWindow w = make_window({32, 32, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  t.update_capacity(s.view(), load, env_for(w));
  const BristleLoadHost lh = load.to_host();
  float prev = 2.f * prm.M_max;
  for (int j = 0; j < n; ++j) {
    const float expect = surface_capacity(prm.M_max, R, heights[j], prm.cell_mass());
    EXPECT_NEAR(lh.capacity[size_t(j)], expect, 1e-5f * prm.M_max) << "height " << heights[j];
    EXPECT_LE(lh.capacity[size_t(j)], prev);
    prev = lh.capacity[size_t(j)];
  }
  EXPECT_FLOAT_EQ(lh.capacity[0], prm.M_max);
  EXPECT_NEAR(lh.capacity[size_t(n - 1)], 0.5f * prm.M_max, 1e-5f * prm.M_max);
}

TEST_F(BristleParticleTest, LiquidSurfaceBelowCutsTheCapacity) {
  // Full cells k = 0..3: the interpolated density crosses 0.5 at z = 4 (between centres 3.5 and 4.5).
  const TransferParams prm;
  const float R = load_radius(prm.M_max, prm.cell_mass());
  PaintWindow w = make_window({16, 16, 12}, {0, 0, 0}, [](int, int, int k) { return k < 4 ? 1.f : 0.f; },
                              Vec3(0.f, 1.f, 0.f));
  const float gaps[] = {0.1f, 0.3f, 0.5f, 0.7f};
  HostSamples h;
  h.resize(1, 4);
  for (int j = 0; j < 4; ++j) h.x[size_t(j)] = Vec3(4.f + 2.f * j, 8.f, 4.f + gaps[j]);
  DeviceSamples s(device_);
  s.upload(h);
  BristleLoad load(device_, 4, prm);
  Transfer t(device_, prm);
  t.update_capacity(s.view(), load, env_for(w));
  const BristleLoadHost lh = load.to_host();
  for (int j = 0; j < 4; ++j) {
    const float expect = surface_capacity(prm.M_max, R, gaps[j], prm.cell_mass());
    EXPECT_NEAR(lh.capacity[size_t(j)], expect, 2e-3f * prm.M_max) << "gap " << gaps[j];
  }
  EXPECT_LT(lh.capacity[0], lh.capacity[1]);
}

TEST_F(BristleParticleTest, AbsorptionConservesMassAndTakesEachParticleOnce) {
  HostSamples h = vertical_brush(3, 16, 0.8f, 16.f, 16.f, 10.f, 3.f);
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  BristleLoad load(device_, s.view().count(), prm);
  // A cloud of small particles around the bristles, some within R_j, some not.
  std::vector<Vec3> xs;
  for (int i = 0; i < 400; ++i) {
    const float a = 0.37f * float(i), r = 0.1f + 1.2f * float(i % 17) / 17.f;
    xs.push_back(Vec3(16.f + 3.f * float(i % 3 - 1) + r * std::cos(a), 16.f + r * std::sin(a),
                      10.f + 0.031f * float(i)));
  }
  const float mk = 2e-10f;
  ParticleStore p(device_);
  p.append(particles_at(xs, mk, Vec3(0.f, 1.f, 0.f), 0.6f));
  query_nearest(s, p, 5.f);
  PaintWindow w = make_window({32, 32, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  t.update_capacity(s.view(), load, env_for(w));
  const double particles_before = p.total_mass(ws_), load_before = load.total_mass(ws_);
  TransferRecord rec;
  t.absorb(s.view(), load, p, 1.f / 60.f);
  t.collect(rec);
  EXPECT_GT(rec.absorbed_count, 0);
  // Each absorbed particle is flagged once and counted once; the sample side equals it.
  const std::vector<uint32_t> dead = p.dead.to_host();
  int64_t n_dead = 0;
  for (int64_t i = 0; i < p.size(); ++i) n_dead += dead[size_t(i)] ? 1 : 0;
  EXPECT_EQ(n_dead, rec.absorbed_count);
  EXPECT_NEAR(rec.absorbed_from_particles, double(n_dead) * mk, 1e-6 * rec.absorbed_from_particles);
  EXPECT_NEAR(rec.absorbed_into_bristles, rec.absorbed_from_particles, 1e-6 * rec.absorbed_from_particles);
  EXPECT_LT(rec.max_closure_error(), 1e-6);
  // Per-sample limit and capacity: no sample took more than absorb_limit particles.
  const BristleLoadHost lh = load.to_host();
  for (size_t j = 0; j < lh.m.size(); ++j) {
    EXPECT_LE(lh.m[j], float(prm.absorb_limit) * mk * 1.0001f);
    if (lh.m[j] > 0.f) {
      EXPECT_NEAR(lh.pigment_y[j], 1.f, 1e-4f) << "absorbed colour: the particles' yellow";
      EXPECT_NEAR(lh.oil[j], 0.6f, 1e-5f);
    }
  }
  // After compaction: paint is conserved (bristles + particles).
  p.compact(ws_);
  EXPECT_NEAR(p.total_mass(ws_) + load.total_mass(ws_), particles_before + load_before, 1e-6 * particles_before);
  EXPECT_EQ(p.size(), int64_t(xs.size()) - n_dead);
}

TEST_F(BristleParticleTest, AbsorptionNeedsTheNearestSampleOnlyWithinTheLargestLoadSphere) {
  // The same cloud absorbed after a nearest-sample query reaching D0 and one reaching only
  // absorb_range(): the same particles go to the same samples (the step queries the latter).
  HostSamples h = vertical_brush(3, 16, 0.8f, 16.f, 16.f, 10.f, 3.f);
  DeviceSamples s(device_);
  s.upload(h);
  // No per-step ticket limit and room in every sample: which particles win a contested sample
  // would otherwise depend on the threads' order, in both runs alike.
  TransferParams prm;
  prm.absorb_limit = 1024;
  const ParticleParams pp;
  ASSERT_LT(prm.absorb_range(), pp.D0);
  std::vector<Vec3> xs;
  for (int i = 0; i < 400; ++i) {
    const float a = 0.37f * float(i), r = 0.1f + 2.5f * float(i % 17) / 17.f;
    xs.push_back(Vec3(16.f + 3.f * float(i % 3 - 1) + r * std::cos(a), 16.f + r * std::sin(a),
                      10.f + 0.031f * float(i)));
  }
  PaintWindow w = make_window({32, 32, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  struct Result {
    std::vector<uint32_t> dead;
    BristleLoadHost load;
  };
  const auto absorb_after_query = [&](float range) {
    BristleLoad load(device_, s.view().count(), prm);
    ParticleStore p(device_);
    p.append(particles_at(xs, 2e-11f, Vec3(0.f, 1.f, 0.f), 0.6f));
    query_nearest(s, p, range);
    Transfer t(device_, prm);
    t.update_capacity(s.view(), load, env_for(w));
    const BristleLoadHost lh = load.to_host();
    for (float R : lh.radius) EXPECT_LE(R, prm.absorb_range() * (1.f + 1e-6f)) << "a load sphere beyond the range";
    TransferRecord rec;
    t.absorb(s.view(), load, p, 1.f / 60.f);
    t.collect(rec);
    EXPECT_GT(rec.absorbed_count, 0);
    return Result{p.dead.to_host(), load.to_host()};
  };
  const Result wide = absorb_after_query(pp.D0), near = absorb_after_query(prm.absorb_range());
  ASSERT_GE(wide.dead.size(), xs.size());
  ASSERT_GE(near.dead.size(), xs.size());
  for (size_t k = 0; k < xs.size(); ++k) EXPECT_EQ(wide.dead[k], near.dead[k]) << "particle " << k;
  ASSERT_EQ(wide.load.m.size(), near.load.m.size());
  for (size_t j = 0; j < wide.load.m.size(); ++j) {  // float atomics: sums in any order
    EXPECT_NEAR(wide.load.m[j], near.load.m[j], 1e-6f * prm.M_max) << "sample " << j;
    EXPECT_NEAR(wide.load.pigment_y[j], near.load.pigment_y[j], 1e-5f) << "sample " << j;
  }
}

TEST_F(BristleParticleTest, AbsorptionStopsAtCapacityAndLimit) {
  HostSamples h;
  h.resize(1, 1);
  h.x[0] = Vec3(8.f, 8.f, 6.f);
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  prm.absorb_limit = 1000;
  BristleLoad load(device_, 1, prm);
  const float R = load_radius(prm.M_max, prm.cell_mass());
  std::vector<Vec3> xs;
  for (int i = 0; i < 40; ++i) xs.push_back(Vec3(8.f + 0.5f * R * std::cos(0.7f * i), 8.f, 6.f + 0.5f * R * std::sin(0.7f * i)));
  const float mk = prm.M_max / 9.5f;  // 40 of them would hold four times the capacity
  ParticleStore p(device_);
  p.append(particles_at(xs, mk, Vec3(1.f, 0.f, 0.f)));
  query_nearest(s, p, 5.f);
  PaintWindow w = make_window({16, 16, 16}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  t.update_capacity(s.view(), load, env_for(w));
  TransferRecord rec;
  t.absorb(s.view(), load, p, 1.f / 60.f);
  t.collect(rec);
  // §5.1: the sample absorbs while m_j < M_j, so it ends within one particle above M_j.
  EXPECT_EQ(rec.absorbed_count, 10);
  EXPECT_GE(load.total_mass(ws_), double(prm.M_max) * (1 - 1e-5));
  EXPECT_LE(load.total_mass(ws_), double(prm.M_max + mk) * (1 + 1e-5));
  EXPECT_EQ(rec.bleeding_count, 0) << "the sample was empty at the start of the step: nothing to bleed";
  // The per-step limit.
  prm.absorb_limit = 3;
  Transfer t3(device_, prm);
  BristleLoad load3(device_, 1, prm);
  ParticleStore p3(device_);
  p3.append(particles_at(xs, mk, Vec3(1.f, 0.f, 0.f)));
  query_nearest(s, p3, 5.f);
  t3.update_capacity(s.view(), load3, env_for(w));
  TransferRecord rec3;
  t3.absorb(s.view(), load3, p3, 1.f / 60.f);
  t3.collect(rec3);
  EXPECT_EQ(rec3.absorbed_count, 3);
  EXPECT_NEAR(load3.total_mass(ws_), 3.0 * mk, 1e-6 * mk);
}

TEST(TransferSweep, FilmPickupTakesOnePassWhateverTheSteps) {
  const float split = 0.5f, R = 0.75f;
  EXPECT_EQ(film_pickup(split, 0.f), 0.f) << "a sample resting on the film sweeps none of it";
  EXPECT_FLOAT_EQ(film_pickup(split, 1.f), 1.f - split) << "a whole pass in one step";
  EXPECT_EQ(film_pickup(1.f, 1.f), 0.f) << "split 1: the film stays on the surface";
  // The share of the chord: a path ending over the particle swept half of it; one passing beside
  // the particle beyond the disc, or stopping short of it, none.
  EXPECT_NEAR(swept_chord_share(0.f, 0.f, 0.f, 3.f, 0.f, R), 0.5f, 1e-6f);
  EXPECT_NEAR(swept_chord_share(0.f, 0.f, 0.f, 0.f, 3.f, R), 0.5f, 1e-6f) << "any direction";
  EXPECT_EQ(swept_chord_share(0.f, 0.8f, 0.f, 3.f, 0.f, R), 0.f) << "beside the path";
  EXPECT_EQ(swept_chord_share(0.f, 0.f, 0.8f, 3.f, 0.f, R), 0.f) << "above the reach";
  EXPECT_EQ(swept_chord_share(1.f, 0.f, 0.f, 3.f, 0.f, R), 0.f) << "ahead of the path";
  EXPECT_EQ(swept_chord_share(-4.f, 0.f, 0.f, 3.f, 0.f, R), 0.f) << "behind the path";
  EXPECT_EQ(swept_chord_share(0.f, 0.f, 0.f, 0.f, 0.f, R), 0.f) << "resting";
  // A pass over a particle cut into steps of any length takes 1 - split of it in all, wherever
  // the particle lies across the band and whatever the phase of the steps' ends against it: the
  // pick-up does not beat with the travel a step.
  for (float travel : {0.3f, 0.625f, 1.25f, 1.6f, 3.f}) {
    for (float e : {0.f, 0.3f, 0.7f}) {
      for (float dz : {0.f, 0.25f}) {
        for (float phase : {0.f, 0.37f, 0.81f}) {
          double survive = 1.0;
          for (int k = 0; k < 40; ++k) {
            const float end = -6.f + (float(k) + phase) * travel;  // the sample's end, x
            survive *= 1.0 - film_pickup(split, swept_chord_share(0.f - end, e, dz, travel, 0.f, R));
          }
          EXPECT_NEAR(survive, split, 1e-5) << "travel " << travel << ", offset " << e << ", dz " << dz;
        }
      }
    }
  }
}

TEST_F(BristleParticleTest, TouchingSampleTakesTheFilmItSweepsWholeParticlesOnly) {
  // One empty sample 0.4 cells over the canvas (its reach R = 0.75: it touches) above a film of
  // 600 light particles. Resting, or sliding with the film, it takes none; sliding over it, a
  // share of them, each whole: no particle is split.
  TransferParams prm;
  prm.absorb_limit = 1024;  // the per-step limit is not what is measured here
  const float dt = 1.f / 60.f, mk = 1e-14f;
  std::vector<Vec3> xs;
  for (int i = 0; i < 600; ++i) {
    const float a = 2.39996323f * float(i), r = 0.6f * std::sqrt((float(i) + 0.5f) / 600.f);
    xs.push_back(Vec3(8.f + r * std::cos(a), 8.f + r * std::sin(a), 0.1f + 0.2f * float(i % 3) / 2.f));
  }
  PaintWindow w = make_window({16, 16, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  const auto taken = [&](Vec3 v_sample, Vec3 v_film, Vec3 end = Vec3(8.f, 8.f, 0.4f)) {
    HostSamples h;
    h.resize(1, 1);
    h.x[0] = end;
    h.v[0] = v_sample;
    DeviceSamples s(device_);
    s.upload(h);
    BristleLoad load(device_, 1, prm);
    ParticleStore p(device_);
    p.append(particles_at(xs, mk, Vec3(0.f, 1.f, 0.f), 0.3f, v_film));
    query_nearest(s, p, 5.f);
    Transfer t(device_, prm);
    TransferEnv env = env_for(w);
    env.dt = dt;
    t.update_capacity(s.view(), load, env);
    const BristleLoadHost lh = load.to_host();
    EXPECT_LT(lh.gap[0], lh.radius[0]) << "the sample touches the canvas";
    EXPECT_GT(lh.capacity[0], 2.f * float(xs.size()) * mk) << "room for all of them";
    TransferRecord rec;
    t.absorb(s.view(), load, p, dt);
    t.collect(rec);
    const ParticleHost ph = p.to_host();
    const std::vector<uint32_t> flags = p.dead.to_host();
    int dead = 0;
    for (size_t k = 0; k < xs.size(); ++k) {
      if (flags[k]) ++dead;
      else EXPECT_EQ(ph.m[k], mk) << "particle " << k << " was split";
    }
    EXPECT_EQ(rec.absorbed_count, dead);
    EXPECT_NEAR(rec.absorbed_into_bristles, double(dead) * mk, 1e-5 * double(dead) * mk);  // float sums
    return double(dead) / double(xs.size());
  };
  const float R = load_radius(prm.M_max, prm.cell_mass());
  EXPECT_EQ(taken(Vec3(), Vec3()), 0.0) << "resting on the film";
  EXPECT_EQ(taken(Vec3(30.f, 0.f, 0.f), Vec3(30.f, 0.f, 0.f)), 0.0) << "carrying the film along";
  // Sliding over it, each particle with the chance of the share of its chord swept; the last
  // case ends 2 cells past the film, beyond its reach: the film along the path is taken too.
  struct Slide {
    float travel, past;
  };
  for (Slide sl : {Slide{0.25f * R, 0.f}, Slide{0.5f * R, 0.f}, Slide{4.f * R, 0.f}, Slide{3.f, 2.f}}) {
    const Vec3 end(8.f + sl.past, 8.f, 0.4f);
    double expect = 0.0;
    for (const Vec3& x : xs)
      expect += film_pickup(prm.split, swept_chord_share(x.x - end.x, x.y - end.y, x.z - end.z, sl.travel, 0.f, R));
    expect /= double(xs.size());
    const double got = taken(Vec3(sl.travel / dt, 0.f, 0.f), Vec3(), end);
    // Binomial spread of 600 draws: sqrt(p (1 - p) / 600) <= 0.021; 4 of it.
    EXPECT_NEAR(got, expect, 0.085) << "slid " << sl.travel << " cells";
    EXPECT_GT(got, sl.past > 0.f ? 0.4 : 0.0) << "slid " << sl.travel << " cells";
  }
}

TEST_F(BristleParticleTest, ASampleBeyondTheWindowLaysNoTrailAtItsWall) {
  // A loaded sample sliding on the canvas leaves a swept deposit inside the window; beyond the
  // window's columns (a brush wider than its window) none, which would land in the wall's column.
  TransferParams prm;
  const float dt = 1.f / 60.f;
  PaintWindow w = make_window({16, 16, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  PaintLoad blue;
  blue.ryb[0] = 0.1f, blue.ryb[1] = 0.15f, blue.ryb[2] = 0.85f;
  blue.load = 1.f;
  const auto sweep = [&](Vec3 at) {
    HostSamples h;
    h.resize(1, 1);
    h.x[0] = at;
    h.v[0] = Vec3(60.f, 0.f, 0.f);  // a cell a step
    DeviceSamples s(device_);
    s.upload(h);
    BristleLoad load(device_, 1, prm);
    load.fill(blue);
    Transfer t(device_, prm);
    TransferEnv env = env_for(w);
    env.dt = dt;
    t.update_capacity(s.view(), load, env);
    const BristleLoadHost lh = load.to_host();
    EXPECT_LT(lh.gap[0], lh.radius[0]) << "the sample touches the canvas at " << at.x << ", " << at.y;
    return lh.sweep[0];
  };
  EXPECT_GT(sweep(Vec3(8.f, 8.f, 0.4f)), 0.f) << "inside: a trail";
  EXPECT_EQ(sweep(Vec3(20.f, 8.f, 0.4f)), 0.f) << "beyond the +x wall";
  EXPECT_EQ(sweep(Vec3(8.f, -3.f, 0.4f)), 0.f) << "beyond the -y wall";
}

TEST_F(BristleParticleTest, SaturatedSampleAbsorbsNoMassButBleedsColour) {
  HostSamples h = vertical_brush(1, 4, 0.8f, 8.f, 8.f, 6.f, 1.f);
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  BristleLoad load(device_, 4, prm);
  PaintLoad blue;
  blue.ryb[0] = 0.f;
  blue.ryb[1] = 0.f;
  blue.ryb[2] = 1.f;
  blue.load = 1.f;
  load.fill(blue);  // m = M' = M: saturated
  std::vector<Vec3> xs;
  for (int j = 0; j < 4; ++j) xs.push_back(h.x[size_t(j)] + Vec3(0.2f, 0.f, 0.f));
  const float mk = 3e-10f;
  ParticleStore p(device_);
  p.append(particles_at(xs, mk, Vec3(0.f, 1.f, 0.f)));
  query_nearest(s, p, 5.f);
  PaintWindow w = make_window({16, 16, 16}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  t.update_capacity(s.view(), load, env_for(w));
  const double load_before = load.total_mass(ws_), part_before = p.total_mass(ws_);
  TransferRecord rec;
  t.absorb(s.view(), load, p, 1.f / 60.f);
  t.collect(rec);
  EXPECT_EQ(rec.absorbed_count, 0);
  EXPECT_EQ(rec.bleeding_count, 4);
  EXPECT_DOUBLE_EQ(load.total_mass(ws_), load_before);
  EXPECT_DOUBLE_EQ(p.total_mass(ws_), part_before);
  const BristleLoadHost lh = load.to_host();
  const ParticleHost ph = p.to_host();
  for (size_t j = 0; j < 4; ++j) {
    EXPECT_GT(lh.pigment_y[j], 0.f) << "the saturated sample picks up yellow";
    EXPECT_LT(lh.pigment_y[j], 0.5f);
    EXPECT_GT(ph.pigment_b[j], 0.f) << "the particle picks up blue";
    EXPECT_GT(ryb_to_rgb(Vec3(ph.pigment_r[j], ph.pigment_y[j], ph.pigment_b[j])).z, 0.f);
  }
  const std::vector<uint32_t> dead = p.dead.to_host();  // the buffer is longer than the store
  for (int64_t k = 0; k < p.size(); ++k) EXPECT_EQ(dead[size_t(k)], 0u);
}

TEST_F(BristleParticleTest, EmissionSettlesInTheBandBelowTheSamples) {
  HostSamples h = vertical_brush(2, 6, 0.8f, 16.f, 16.f, 8.f, 4.f, Vec3(30.f, -5.f, 0.f));
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  const int64_t ns = s.view().count();
  BristleLoad load(device_, ns, prm);
  // Three times the capacity, in orange with oil 0.4.
  BristleLoadHost lh = load.to_host();
  for (int64_t j = 0; j < ns; ++j) {
    lh.m[size_t(j)] = 3.f * prm.M_max;
    lh.pigment_r[size_t(j)] = 0.8f;
    lh.pigment_y[size_t(j)] = 0.6f;
    lh.pigment_b[size_t(j)] = 0.f;
    lh.oil[size_t(j)] = 0.4f;
  }
  load.from_host(lh);
  ParticleStore p(device_);
  PaintWindow w = make_window({32, 32, 16}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  const TransferEnv env = env_for(w);
  const double total = load.total_mass(ws_);
  int steps = 0;
  for (; steps < 200; ++steps) {
    t.update_capacity(s.view(), load, env);
    TransferRecord rec;
    const int64_t before = p.size();
    t.emit(s.view(), load, p, env, rec);
    t.collect(rec);
    if (steps == 0) EXPECT_EQ(rec.emitted_count, ns * prm.emit_limit) << "per-step limit";
    EXPECT_LT(rec.max_closure_error(), 1e-6);
    EXPECT_EQ(p.size() - before, rec.emitted_count);
    if (rec.emitted_count == 0) break;
  }
  EXPECT_LT(steps, 200);
  // Load within [M, (1 + eps) M]; mass conserved.
  lh = load.to_host();
  for (int64_t j = 0; j < ns; ++j) {
    EXPECT_GE(lh.m[size_t(j)], lh.capacity[size_t(j)] * (1.f - 1e-5f));
    EXPECT_LE(lh.m[size_t(j)], lh.capacity[size_t(j)] * (1.f + prm.epsilon) * (1.f + 1e-5f));
  }
  EXPECT_NEAR(load.total_mass(ws_) + p.total_mass(ws_), total, 1e-6 * total);
  // Every particle lies in the lower half-ball of some sample, with its colour, oil and velocity.
  const ParticleHost ph = p.to_host();
  for (size_t k = 0; k < ph.size(); ++k) {
    bool found = false;
    for (int64_t j = 0; j < ns && !found; ++j) {
      const Vec3 d = ph.x[k] - h.x[size_t(j)];
      if (length(d) <= lh.radius[size_t(j)] * 1.0001f && d.z <= 1e-6f) found = true;
    }
    EXPECT_TRUE(found) << "particle " << k << " is not below any sample";
    EXPECT_FLOAT_EQ(ph.pigment_r[k], 0.8f);
    EXPECT_FLOAT_EQ(ph.pigment_y[k], 0.6f);
    EXPECT_FLOAT_EQ(ph.oil[k], 0.4f);
    EXPECT_FLOAT_EQ(ph.v[k].x, 30.f);
    EXPECT_FLOAT_EQ(ph.v[k].y, -5.f);
    EXPECT_LE(ph.m[k], prm.emit_mass * (1.f + 1e-6f));
  }
}

TEST_F(BristleParticleTest, EmissionRespectsTheParticleLimit) {
  HostSamples h = vertical_brush(4, 8, 0.8f, 16.f, 16.f, 8.f, 2.f);
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  BristleLoad load(device_, s.view().count(), prm);
  BristleLoadHost lh = load.to_host();
  for (float& m : lh.m) m = 2.f * prm.M_max;
  load.from_host(lh);
  ParticleStore p(device_, 50);
  PaintWindow w = make_window({32, 32, 16}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  const double total = load.total_mass(ws_);
  t.update_capacity(s.view(), load, env_for(w));
  TransferRecord rec;
  t.emit(s.view(), load, p, env_for(w), rec);
  t.collect(rec);
  EXPECT_EQ(p.size(), 50);
  EXPECT_EQ(rec.emitted_count, 50);
  EXPECT_EQ(rec.emission_dropped, 32 * prm.emit_limit - 50);
  EXPECT_NEAR(load.total_mass(ws_) + p.total_mass(ws_), total, 1e-6 * total);
}

TEST_F(BristleParticleTest, EmissionPatternIsInTheLowerHalfBall) {
  const int P = 16;
  Vec3 mean(0.f, 0.f, 0.f);
  for (int s = 0; s < P; ++s) {
    const Vec3 q = emission_pattern_point(s, P);
    EXPECT_LE(q.z, 0.f);
    EXPECT_LE(length(q), 1.f + 1e-6f);
    EXPECT_GE(length(q), 0.45f);
    mean += q / float(P);
  }
  // Spread around the vertical axis: the horizontal mean is small next to the radius.
  EXPECT_LT(std::sqrt(mean.x * mean.x + mean.y * mean.y), 0.2f);
  EXPECT_LT(mean.z, -0.2f);
}

// The pattern's slots a sample starts a step from (docs/TRANSFER.md "Pattern"): every slot in
// its share over many steps, a step's particles on consecutive slots, and no cycle with the step.
// A start that cycled with the step, (j + step n) mod P, laid the pattern's offsets along a slow
// stroke in a P-step cycle: lines across it (the flat broadside's 2-cell line at 15 mm/s).
TEST_F(BristleParticleTest, PatternSlotsAreDrawnAStepNotCycled) {
  const int P = 16, steps = 1600;
  for (int64_t j : {int64_t(0), int64_t(7), int64_t(12345)}) {
    std::vector<int> start(steps), count(P, 0);
    for (int t = 0; t < steps; ++t) {
      start[size_t(t)] = pattern_slot(j, t, 0, P);
      ++count[size_t(start[size_t(t)])];
      for (int i = 1; i < 4; ++i) EXPECT_EQ(pattern_slot(j, t, i, P), (start[size_t(t)] + i) % P);
    }
    for (int c : count) EXPECT_NEAR(c, steps / P, 0.3 * steps / P) << "sample " << j;
    // Steps d apart share their start about 1 / P of the time for every lag d: no lag repeats it.
    for (int d = 1; d <= 2 * P; ++d) {
      int same = 0;
      for (int t = 0; t + d < steps; ++t) same += start[size_t(t)] == start[size_t(t + d)];
      EXPECT_LT(double(same) / double(steps - d), 3.0 / P) << "sample " << j << ", lag " << d;
    }
  }
}

TEST_F(BristleParticleTest, BrushWithoutPaintLeavesNone) {
  HostSamples h = vertical_brush(4, 16, 0.8f, 16.f, 16.f, 0.f, 2.f, Vec3(50.f, 0.f, 0.f));
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  BristleLoad load(device_, s.view().count(), prm);
  ParticleStore p(device_);
  PaintWindow w = make_window({32, 32, 16}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  Transfer t(device_, prm);
  for (int i = 0; i < 5; ++i) {
    TransferRecord rec = t.step(s.view(), load, p, env_for(w, 10.f));
    t.collect(rec);
    EXPECT_EQ(rec.emitted_count + rec.to_particles_count + rec.absorbed_count + rec.to_grid_count, 0);
  }
  EXPECT_EQ(p.size(), 0);
  EXPECT_EQ(load.total_mass(ws_), 0.0);
  EXPECT_EQ(w.total_density(ws_), 0.0);
}

}  // namespace
}  // namespace wb::test
