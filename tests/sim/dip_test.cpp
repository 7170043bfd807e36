// Dipping a loaded brush into a well of another colour (docs/TRANSFER.md "Dipping"), measured on
// the paint the next dab leaves on the canvas: the well's paint replaces what the pile reaches on
// the tips and the outside of the tuft, so the new colour shows at once, streaked with the old
// that the inner bristles keep. Small brush, short dabs (CI on two CPU cores).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/brush/brush_model.h"
#include "core/canvas/window.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

constexpr float kDt = 1.f / 60.f;
constexpr float kY = 32.f;
constexpr int kW = 256, kH = 64;

class DipTest : public SimulatorTest {
 protected:
  static PaintLoad well(Vec3 ryb) {
    PaintLoad p;
    p.ryb[0] = ryb.x, p.ryb[1] = ryb.y, p.ryb[2] = ryb.z;
    p.oil = 0.3f;
    p.load = 1.f;
    return p;
  }
  /// A dab: the brush lands at x in 4 steps, is pressed and pulled 12 cells in 12 steps, lifts.
  static void dab(Simulator& sim, float x) {
    const BrushSpec& b = sim.config().brush;
    for (int i = 1; i <= 4; ++i) sim.step(pose_at(b, x, kY, 0.2f * float(i)), kDt);
    for (int i = 1; i <= 12; ++i) sim.step(pose_at(b, x + float(i), kY, 0.8f), kDt);
    for (int i = 0; i < 6; ++i) sim.step(pose_at(b, x + 12.f, kY, 0.f, false), kDt);
  }
  /// Density-weighted mean RYB of the canvas's paint in columns [x0, x1), and the share of the
  /// painted columns whose own mean lies nearer `a` than `b` (streaks of the old colour).
  struct Patch {
    Vec3 mean;
    double mass = 0;
    std::vector<Vec3> columns;  ///< the mean of each painted column
  };
  Patch patch(Simulator& sim, int x0, int x1) {
    const CanvasDims d = sim.canvas().dims();
    PaintWindow w(device_, Int3{d.width, d.height, d.depth});
    SimulatorTestAccess::canvas(sim).gather(w);
    const auto f = w.to_host();  // density, r, y, b, oil, dryness
    Patch p;
    double s[3] = {0, 0, 0};
    for (int y = 0; y < d.height; ++y)
      for (int x = x0; x < x1; ++x) {
        double cm = 0, cs[3] = {0, 0, 0};
        for (int z = 0; z < d.depth; ++z) {
          const size_t id = (size_t(z) * d.height + y) * d.width + x;
          const double rho = f[0][id];
          cm += rho;
          for (int c = 0; c < 3; ++c) cs[c] += rho * f[1 + c][id];
        }
        p.mass += cm;
        for (int c = 0; c < 3; ++c) s[c] += cs[c];
        if (cm > 0.5) p.columns.push_back(Vec3(float(cs[0] / cm), float(cs[1] / cm), float(cs[2] / cm)));
      }
    p.mean = p.mass > 0 ? Vec3(float(s[0] / p.mass), float(s[1] / p.mass), float(s[2] / p.mass)) : Vec3();
    return p;
  }
  /// How far c lies along the way from a to b (RYB): 0 at a, 1 at b.
  static double along(Vec3 c, Vec3 a, Vec3 b) { return dot(c - a, b - a) / dot(b - a, b - a); }
};

// The brush in its rest pose: the tips of the outer bristles go deepest into the pile, the
// samples above dip_depth not at all, the tuft's axis a third as much as its outline.
TEST_F(DipTest, ExposureIsDeepestAtTheOuterTips) {
  const BrushSpec b = default_brush(BrushShape::Round);
  const BristleLayout L = build_bristle_layout(b);
  const int S = b.samples_per_bristle;
  const std::vector<float> e = dip_exposure(L, S, 20.f);
  ASSERT_EQ(e.size(), size_t(b.bristles) * size_t(S));
  float outer_tip = 0.f, inner_tip = 1.f, roots = 0.f;
  float r_max = 0.f;
  for (const Vec3& r : L.root) r_max = std::max(r_max, std::hypot(r.x, r.y));
  for (int k = 0; k < b.bristles; ++k) {
    const float r = std::hypot(L.root[size_t(k)].x, L.root[size_t(k)].y) / r_max;
    const float tip = e[size_t(k) * S + S - 1];
    if (r > 0.95f) outer_tip = std::max(outer_tip, tip);
    if (r < 0.1f) inner_tip = std::min(inner_tip, tip);
    roots = std::max(roots, e[size_t(k) * S]);
    for (int j = 1; j < S; ++j) ASSERT_GE(e[size_t(k) * S + j] + 1e-6f, e[size_t(k) * S + j - 1]) << "deeper towards the tip";
  }
  EXPECT_GT(outer_tip, 0.85f);
  EXPECT_LT(inner_tip, 0.45f);
  EXPECT_EQ(roots, 0.f) << "the pile does not reach the ferrule";
}

// A brush still full of red, dabbed once and dipped in blue without cleaning: its next dab is
// mostly blue; after a clean and a dip it is blue. The books close through every dip.
TEST_F(DipTest, ADipChangesTheColourOfALoadedBrush) {
  const Vec3 red(0.9f, 0.1f, 0.05f), blue(0.f, 0.f, 1.f);
  const SimConfig c = small_config(CanvasDims{kW, kH, 16});
  Simulator sim(c, pose_at(c.brush, 40.f, kY, 0.f, false));
  sim.load_paint(well(red));
  dab(sim, 30.f);
  sim.dip(well(blue));
  dab(sim, 120.f);
  sim.clean();
  sim.dip(well(blue));
  dab(sim, 210.f);
  sim.settle();
  const Patch first = patch(sim, 10, 75), dipped = patch(sim, 100, 165), clean = patch(sim, 190, kW);
  ASSERT_GT(first.mass, 20.0);
  ASSERT_GT(dipped.mass, 20.0);
  ASSERT_GT(clean.mass, 20.0);
  const double t1 = along(first.mean, red, blue), t2 = along(dipped.mean, red, blue);
  const double t3 = along(clean.mean, red, blue);
  // The columns of the dipped dab: some carry more of the old red than the dab's mean (streaks).
  double lo = 1, hi = 0;
  for (const Vec3& col : dipped.columns) lo = std::min(lo, along(col, red, blue)), hi = std::max(hi, along(col, red, blue));
  std::printf("[ dip ] red dab %.3f, dipped in blue %.3f (columns %.3f..%.3f), cleaned and dipped %.3f of the way "
              "red -> blue; paint %.1f / %.1f / %.1f cells\n",
              t1, t2, lo, hi, t3, first.mass, dipped.mass, clean.mass);
  EXPECT_LT(t1, 0.02);
  EXPECT_GE(t2, 0.6) << "a dip changes the colour a loaded brush paints";
  EXPECT_LT(t2, 0.98) << "the old paint is still in the bristles";
  EXPECT_LT(lo, t2 - 0.05) << "the old paint comes out in streaks";
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(clean.mean[k], blue[k], 0.05f) << k;
  EXPECT_LE(sim.books().max_drift(), 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
}

}  // namespace
}  // namespace wb::test
