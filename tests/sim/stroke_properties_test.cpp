// Properties of a painted stroke (docs/TRANSFER.md "Swept contact"), measured on the paint the
// stroke leaves on the canvas: the same stroke cut into more or fewer sub-steps paints the same,
// and covers its track. Small brush, short strokes (CI on two CPU cores).
#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

constexpr float kDt = 1.f / 60.f;
constexpr int kW = 240, kH = 64;
constexpr float kY = 32.f, kX0 = 30.f, kX1 = 200.f;

class StrokePropertiesTest : public SimulatorTest {
 protected:
  /// Column paint (cells) per canvas column after a straight stroke along x at `speed` cells/s,
  /// its sub-steps moving at most `max_move` cells; the brush lands, drags, lifts.
  std::vector<float> paint_stroke(float speed, float max_move) {
    const SimConfig c = small_config(CanvasDims{kW, kH, 16});
    Simulator sim(c, pose_at(c.brush, kX0, kY, 0.f, false));
    sim.load_paint(red());
    const float p = 0.6f;
    for (int i = 1; i <= 4; ++i) sim.step(pose_at(c.brush, kX0, kY, p * 0.25f * float(i)), kDt);
    const int substeps = std::max(1, int(std::ceil(speed * kDt / max_move)));
    std::vector<BrushPose> poses(static_cast<size_t>(substeps), pose_at(c.brush, kX0, kY, p));
    float x = kX0;
    while (x < kX1) {
      for (int k = 0; k < substeps; ++k)
        poses[size_t(k)] = pose_at(c.brush, std::min(kX1, x + speed * kDt * float(k + 1) / float(substeps)), kY, p);
      sim.step(poses.data(), substeps, kDt);
      x += speed * kDt;
    }
    for (int i = 0; i < 6; ++i) sim.step(pose_at(c.brush, kX1, kY, 0.f, false), kDt);
    sim.settle();
    EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
    EXPECT_EQ(sim.counters().nonfinite_events, 0);
    PaintWindow w(device_, Int3{kW, kH, 16});
    sim.canvas().gather(w);
    const auto host = w.to_host();
    std::vector<float> col(size_t(kW) * kH, 0.f);
    for (int z = 0; z < 16; ++z)
      for (int y = 0; y < kH; ++y)
        for (int xx = 0; xx < kW; ++xx) col[size_t(y) * kW + xx] += host[0][(size_t(z) * kH + y) * kW + xx];
    return col;
  }
  /// Share of the track's central band (half the brush width) holding at least a tenth of a
  /// cell of paint.
  static double coverage(const std::vector<float>& col) {
    int n = 0, covered = 0;
    for (int y = int(kY) - 3; y <= int(kY) + 3; ++y)
      for (int x = int(kX0) + 30; x < int(kX1) - 20; ++x, ++n) covered += col[size_t(y) * kW + x] >= 0.1f;
    return double(covered) / n;
  }
};

TEST_F(StrokePropertiesTest, SameStrokeWithMoreOrFewerSubstepsPaintsTheSame) {
  // 160 mm/s, sub-steps of at most 1, 2 and 4 cells (14, 7 and 4 sub-steps a step).
  const std::vector<float> a = paint_stroke(800.f, 1.f), b = paint_stroke(800.f, 2.f), c = paint_stroke(800.f, 4.f);
  std::printf("coverage of the track: %.0f %%, %.0f %%, %.0f %%\n", 100 * coverage(a), 100 * coverage(b), 100 * coverage(c));
  auto total = [](const std::vector<float>& v) { double s = 0; for (float x : v) s += x; return s; };
  auto l1 = [](const std::vector<float>& u, const std::vector<float>& v) {
    double d = 0, s = 0;
    for (size_t i = 0; i < u.size(); ++i) d += std::fabs(u[i] - v[i]), s += u[i];
    return d / s;
  };
  std::printf("paint on the canvas: %.1f, %.1f, %.1f cells; column L1 to the middle: %.3f, %.3f\n", total(a), total(b),
              total(c), l1(b, a), l1(b, c));
  EXPECT_NEAR(total(a), total(b), 0.1 * total(b));
  EXPECT_NEAR(total(c), total(b), 0.1 * total(b));
  EXPECT_LT(l1(b, a), 0.35);
  EXPECT_LT(l1(b, c), 0.35);
  EXPECT_GE(coverage(b), 0.9) << "a continuous layer along the track at 160 mm/s";
}

}  // namespace
}  // namespace wb::test
