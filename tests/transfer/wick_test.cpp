// Wicking along the bristles (docs/TRANSFER.md "Wicking"): the implicit per-bristle flow of the
// load from fuller to emptier samples keeps each bristle's paint, never makes a load negative,
// keeps saturations within their old range, spreads them towards one value, and carries colour.
#include <random>

#include "transfer/transfer_fixture.h"

namespace wb::test {

class WickTest : public TransferTest {
 protected:
  /// `bristles` straight bristles of `per` samples sliding along the canvas at `vel` cells/s.
  SampleView layout(int bristles, int per, Vec3 vel = Vec3()) {
    HostSamples h;
    h.resize(bristles, per);
    for (int b = 0; b < bristles; ++b)
      straight_bristle(h, b, Vec3(10.f + b, 10.f, 1.f), Vec3(0.f, 0.f, 1.f), Vec3(1.f, 0.f, 0.f), 0.5f, vel, Vec3());
    samples_.upload(h);
    return samples_.view();
  }
  DeviceSamples samples_{device_};
  /// One bristle of `per` samples at full capacity, full of paint except its emptied tip (sample 0).
  static BristleLoadHost emptied_tip(int per, const TransferParams& prm) {
    BristleLoadHost h;
#define WB_X(name, doc) h.name.assign(size_t(per), 0.f);
    WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
    for (int i = 0; i < per; ++i) {
      h.potential[i] = h.capacity[i] = prm.M_max;
      h.radius[i] = 0.75f;
      h.m[i] = i == 0 ? 0.f : prm.M_max;
    }
    return h;
  }

  static BristleLoadHost random_load(int n, std::mt19937& rng, const TransferParams& prm) {
    std::uniform_real_distribution<float> U(0.f, 1.f);
    BristleLoadHost h;
#define WB_X(name, doc) h.name.assign(size_t(n), 0.f);
    WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
    for (int i = 0; i < n; ++i) {
      h.potential[i] = prm.M_max * (0.3f + 0.7f * U(rng));
      h.capacity[i] = h.potential[i];
      h.radius[i] = 0.75f;
      h.m[i] = h.potential[i] * U(rng) * U(rng) * 1.5f;  // some over-full, some nearly empty
      h.pigment_r[i] = U(rng);
      h.pigment_y[i] = U(rng);
      h.pigment_b[i] = U(rng);
      h.oil[i] = U(rng);
    }
    return h;
  }
};

TEST_F(WickTest, KeepsEachBristlesPaintAndSaturationsInRange) {
  std::mt19937 rng(11);
  const int B = 24, per = 64;
  TransferParams prm;
  for (float k_dt : {0.f, 0.5f, 30.f, 1e4f, 1e6f}) {
    const BristleLoadHost before = random_load(B * per, rng, prm);
    BristleLoad load(device_, B * per, prm);
    load.from_host(before);
    prm.wick_rate = k_dt;
    Transfer t(device_, prm);
    t.wick(layout(B, per), load, 1.f);
    const BristleLoadHost after = load.to_host();
    for (int b = 0; b < B; ++b) {
      double m0 = 0, m1 = 0;
      float s_lo = 1e30f, s_hi = 0.f, s1_lo = 1e30f, s1_hi = 0.f;
      for (int i = b * per; i < (b + 1) * per; ++i) {
        m0 += before.m[i];
        m1 += after.m[i];
        ASSERT_GE(after.m[i], 0.f);
        const float s0 = before.m[i] / before.potential[i], s1 = after.m[i] / after.potential[i];
        s_lo = std::min(s_lo, s0), s_hi = std::max(s_hi, s0);
        s1_lo = std::min(s1_lo, s1), s1_hi = std::max(s1_hi, s1);
      }
      EXPECT_NEAR(m1, m0, 1e-5 * m0) << "k dt = " << k_dt << ", bristle " << b;
      // Maximum principle of the implicit diffusion: no new extremes of saturation.
      EXPECT_GE(s1_lo, s_lo * (1 - 1e-4f) - 1e-6f) << "k dt = " << k_dt;
      EXPECT_LE(s1_hi, s_hi * (1 + 1e-4f) + 1e-6f) << "k dt = " << k_dt;
      if (k_dt == 0.f) EXPECT_EQ(m1, m0);
      // The slowest mode of the chain decays by 1 / (1 + k dt pi^2 / per^2) per step: 1/25 at 1e4.
      if (k_dt == 1e4f) EXPECT_LT(s1_hi - s1_lo, 0.1f * (s_hi - s_lo)) << "a fast flow evens the bristle out";
      if (k_dt > 0.f) EXPECT_LT(s1_hi - s1_lo, s_hi - s_lo) << "the spread of saturations shrinks";
    }
  }
}

TEST_F(WickTest, SolvesTheBackwardEulerSystemOfEachBristle) {
  // The parallel reduction against Thomas's algorithm in double on the host: the loads after the
  // flow, m_i + F_{i-1} - F_i with F_i = g_i (s_i - s_{i+1}), for bristles of any length (not only
  // powers of two), a slow and a fast flow, with a swept contact's sink on some samples.
  std::mt19937 rng(5);
  for (int per : {1, 2, 5, 37, 128}) {
    for (float k_dt : {0.5f, 1e4f}) {
      const int B = 7;
      TransferParams prm;
      prm.wick_rate = k_dt;
      BristleLoadHost before = random_load(B * per, rng, prm);
      std::uniform_real_distribution<float> U(0.f, 1.f);
      for (float& sg : before.sweep) sg = U(rng) < 0.2f ? 2.f * U(rng) : 0.f;
      BristleLoad load(device_, B * per, prm);
      load.from_host(before);
      Transfer t(device_, prm);
      t.wick(layout(B, per), load, 1.f);  // at rest: g = k dt min(M_a, M_b)
      const BristleLoadHost after = load.to_host();
      for (int b = 0; b < B; ++b) {
        const int o = b * per;
        const size_t n = size_t(per);
        std::vector<double> g(n, 0.0), cp(n), dp(n), s(n);
        for (int i = 0; i + 1 < per; ++i)
          g[i] = double(k_dt) * std::min(double(before.capacity[o + i]), double(before.capacity[o + i + 1]));
        for (int i = 0; i < per; ++i) {  // Thomas, forward
          const double gp = i > 0 ? g[i - 1] : 0.0;
          const double diag = double(before.capacity[o + i]) * (1.0 + double(before.sweep[o + i])) + gp + g[i] -
                              (i > 0 ? gp * cp[i - 1] : 0.0);
          cp[i] = g[i] / diag;
          dp[i] = (double(before.m[o + i]) + (i > 0 ? gp * dp[i - 1] : 0.0)) / diag;
        }
        for (int i = per - 1; i >= 0; --i) s[i] = dp[i] + (i + 1 < per ? cp[i] * s[i + 1] : 0.0);
        double total = 0.0;
        for (int i = 0; i < per; ++i) total += before.m[o + i];
        // Single precision: F = g (s_i - s_{i+1}) loses k dt times float's epsilon of a load to
        // the difference of two near-equal saturations, in any solver.
        const double tol = (1e-6 * (1.0 + k_dt)) * total / per;
        for (int i = 0; i < per; ++i) {
          const double F_left = i > 0 ? g[i - 1] * (s[i - 1] - s[i]) : 0.0;
          const double F = i + 1 < per ? g[i] * (s[i] - s[i + 1]) : 0.0;
          const double m = double(before.m[o + i]) + F_left - F;
          ASSERT_NEAR(after.m[o + i], m, tol + 1e-5 * m)
              << "per " << per << ", k dt " << k_dt << ", bristle " << b << ", sample " << i;
          const double sg = before.sweep[o + i];
          ASSERT_NEAR(after.sweep[o + i], m * sg / (1.0 + sg), tol + 1e-5 * m) << "the sink's share";
        }
      }
    }
  }
}

TEST_F(WickTest, FeedsAnEmptiedTipWithTheBristlesColour) {
  // One bristle: the tip (sample 0) emptied, the rest full of blue paint. The tip fills from
  // its neighbours and turns blue; samples far up only give, so they keep their colour.
  const int per = 32;
  TransferParams prm;
  BristleLoadHost h = emptied_tip(per, prm);
  for (int i = 0; i < per; ++i) {
    h.pigment_b[i] = i == 0 ? 0.f : 0.9f;
    h.pigment_y[i] = i == 0 ? 0.8f : 0.f;
    h.oil[i] = i == 0 ? 0.f : 0.4f;
  }
  BristleLoad load(device_, per, prm);
  load.from_host(h);
  prm.wick_rate = 2000.f;
  Transfer t(device_, prm);
  t.wick(layout(1, per), load, 1.f / 60.f);
  const BristleLoadHost a = load.to_host();
  EXPECT_GT(a.m[0], 0.3f * prm.M_max) << "k dt = 33: the tip refills within a step";
  EXPECT_LT(a.m[0], prm.M_max);
  EXPECT_GT(a.pigment_b[0], 0.5f) << "the paint that came in is blue";
  EXPECT_LT(a.pigment_y[0], 0.8f);
  EXPECT_GT(a.oil[0], 0.f);
  EXPECT_LT(a.m[1], prm.M_max);
  EXPECT_FLOAT_EQ(a.pigment_b[per - 1], 0.9f) << "a giver keeps its colour";
  EXPECT_FLOAT_EQ(a.pigment_y[per - 1], 0.f);
  // Saturation rises monotonically from the tip up.
  for (int i = 1; i < per; ++i) EXPECT_GE(a.m[i], a.m[i - 1] * (1 - 1e-5f));
}

TEST_F(WickTest, SlidingPumpsPaintDownAHeldBristleDoesNotLeak) {
  // Drag pumping: with no rate per second, an emptied tip refills only while the bristle
  // slides, by an amount set by the distance slid, not by the time taken.
  const int per = 32;
  TransferParams prm;
  prm.wick_rate = 0.f;
  prm.wick_slide = 100.f;
  const BristleLoadHost h = emptied_tip(per, prm);
  Transfer t(device_, prm);
  auto tip_after = [&](Vec3 vel, float dt) {
    BristleLoad load(device_, per, prm);
    load.from_host(h);
    t.wick(layout(1, per, vel), load, dt);
    return load.to_host().m[0];
  };
  EXPECT_EQ(tip_after(Vec3(), 1.f / 60.f), 0.f) << "a bristle at rest does not pump";
  const float slow = tip_after(Vec3(30.f, 0.f, 0.f), 1.f / 15.f);   // 2 cells slid in 1/15 s
  const float fast = tip_after(Vec3(120.f, 0.f, 0.f), 1.f / 60.f);  // 2 cells slid in 1/60 s
  EXPECT_GT(slow, 0.3f * prm.M_max) << "two cells of sliding refill the tip";
  EXPECT_NEAR(fast, slow, 1e-4f * prm.M_max) << "the same distance slid pumps the same paint";
}

TEST_F(WickTest, RejectsBadInput) {
  TransferParams prm;
  BristleLoad load(device_, 8, prm);
  Transfer t(device_, prm);
  EXPECT_THROW(t.wick(layout(1, 4), load, 0.1f), Error) << "sample count differs from the load";
  EXPECT_THROW(t.wick(layout(2, 4), load, std::nanf("")), Error);
  prm.wick_rate = -1.f;
  EXPECT_THROW(Transfer(device_, prm), Error);
}

}  // namespace wb::test
