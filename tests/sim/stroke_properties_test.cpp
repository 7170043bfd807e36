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
/// The stroke's body: past the landing blob, while the small brush still holds paint (its
/// load lays about 30 mm of track, then runs out).
constexpr int kBody0 = int(kX0) + 30, kBody1 = int(kX0) + 110;

class StrokePropertiesTest : public SimulatorTest {
 protected:
  /// Column paint (cells) per canvas column after a straight stroke along x at `speed` cells/s,
  /// its sub-steps moving at most `max_move` cells; the brush lands, drags, lifts.
  std::vector<float> paint_stroke(float speed, float max_move) {
    SimConfig c = small_config(CanvasDims{kW, kH, 16});
    if (getenv("WICK")) c.params.transfer.wick_rate = atof(getenv("WICK"));
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
    std::printf("brush left %.3g kg of %.3g\n", sim.books().steps().back().census.bristles, sim.books().expected_total());
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
    if (getenv("PROFILE")) {
      for (int x0 = 0; x0 < kW; x0 += 10) {
        double v = 0;
        for (int y = 0; y < kH; ++y)
          for (int x = x0; x < x0 + 10; ++x) v += col[size_t(y) * kW + x];
        std::printf("%5.1f", v / 10);
      }
      std::printf("\n");
    }
    if (getenv("DUMP")) {
      char name[64];
      std::snprintf(name, sizeof name, "/tmp/probe/col_%d_%d.pgm", int(speed), int(max_move));
      FILE* f = std::fopen(name, "wb");
      std::fprintf(f, "P5 %d %d 255\n", kW, kH);
      for (float v : col) std::fputc(int(std::min(255.f, v * 40.f)), f);
      std::fclose(f);
    }
    return col;
  }
  /// Share of the track's central band (half the brush width) holding at least a tenth of a
  /// cell of paint.
  static double coverage(const std::vector<float>& col) {
    int n = 0, covered = 0;
    for (int y = int(kY) - 3; y <= int(kY) + 3; ++y)
      for (int x = kBody0; x < kBody1; ++x, ++n) covered += col[size_t(y) * kW + x] >= 0.1f;
    return double(covered) / n;
  }
};

TEST_F(StrokePropertiesTest, SameStrokeWithMoreOrFewerSubstepsPaintsTheSame) {
  // 160 mm/s, sub-steps of at most 1, 2 and 4 cells (14, 7 and 4 sub-steps a step).
  const std::vector<float> a = paint_stroke(800.f, 1.f), b = paint_stroke(800.f, 2.f), c = paint_stroke(800.f, 4.f);
  std::printf("coverage of the track: %.0f %%, %.0f %%, %.0f %%\n", 100 * coverage(a), 100 * coverage(b), 100 * coverage(c));
  auto total = [](const std::vector<float>& v) { double s = 0; for (float x : v) s += x; return s; };
  // L1 of the paint per 4 x 4-cell block (0.8 mm, a third of the brush's width): the same
  // painting, whatever particle lands in which cell.
  auto l1 = [](const std::vector<float>& u, const std::vector<float>& v) {
    double d = 0, s = 0;
    for (int by = 0; by < kH; by += 4)
      for (int bx = 0; bx < kW; bx += 4) {
        double su = 0, sv = 0;
        for (int y = by; y < by + 4; ++y)
          for (int x = bx; x < bx + 4; ++x) su += u[size_t(y) * kW + x], sv += v[size_t(y) * kW + x];
        d += std::fabs(su - sv), s += su;
      }
    return d / s;
  };
  std::printf("paint on the canvas: %.1f, %.1f, %.1f cells; block L1 to the middle: %.3f, %.3f\n", total(a), total(b),
              total(c), l1(b, a), l1(b, c));
  EXPECT_NEAR(total(a), total(b), 0.1 * total(b));
  EXPECT_NEAR(total(c), total(b), 0.1 * total(b));
  EXPECT_LT(l1(b, a), 0.3);
  EXPECT_LT(l1(b, c), 0.3);
  EXPECT_GE(coverage(b), 0.9) << "a continuous layer along the track at 160 mm/s";
}

TEST_F(StrokePropertiesTest, SameStrokeAtAnySpeedLaysTheSameLayer) {
  // 40, 160 and 400 mm/s (200, 800 and 2000 cells/s), sub-steps of at most 2 cells.
  const float speeds[] = {200.f, 800.f, 2000.f};
  double per_length[3], cover[3];
  for (int i = 0; i < 3; ++i) {
    const std::vector<float> col = paint_stroke(speeds[i], 2.f);
    double body = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = kBody0; x < kBody1; ++x) body += col[size_t(y) * kW + x];
    per_length[i] = body / (kBody1 - kBody0);
    cover[i] = coverage(col);
    std::printf("%4.0f mm/s: %.2f cells^2 of paint per cell of track, coverage %.0f %%\n", speeds[i] * 0.2f,
                per_length[i], 100 * cover[i]);
  }
  const double lo = *std::min_element(per_length, per_length + 3), hi = *std::max_element(per_length, per_length + 3);
  EXPECT_LE(hi, 2 * lo) << "volume per unit length within a factor of 2 across speeds";
  for (double c : cover) EXPECT_GE(c, 0.9);
}

}  // namespace
}  // namespace wb::test
