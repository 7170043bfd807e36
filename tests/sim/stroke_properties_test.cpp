// Properties of a painted stroke (docs/TRANSFER.md "Swept contact"), measured on the paint the
// stroke leaves on the canvas: the same stroke cut into more or fewer sub-steps paints the same,
// and covers its track. Small brush, short strokes (CI on two CPU cores).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/io/stroke.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

constexpr float kDt = 1.f / 60.f;
constexpr int kW = 240, kH = 64;
constexpr float kY = 32.f, kX0 = 30.f, kX1 = 200.f;
/// The stroke's body: past the landing blob, while the small brush still holds paint (its
/// load lays about 30 mm of track, then runs out).
constexpr int kBody0 = int(kX0) + 30, kBody1 = int(kX0) + 110;

/// A straight stroke along x at y = kY: the brush lands in 4 steps, drags from kX0 to kX1 at
/// `speed` cells/s, lifts.
struct Stroke {
  float speed = 800.f;     ///< cells/s
  float max_move = 2.f;    ///< most cells a sub-step moves
  float pressure = 0.6f;
  float twist = 0.f;       ///< degrees: 90 pulls a flat broadside (its width across the stroke)
  float y = kY;            ///< the track's row, cells
  float load = 1.f;
  std::optional<BrushSpec> brush;  ///< none: the scene's small round brush
  bool particles = true;   ///< false: grid-only paint (Fig. 7a/c)
  float dt = kDt;          ///< simulation step, s
  float ease = 0.f;        ///< cells over which the brush speeds up from rest (constant acceleration)
  float end = kX1;         ///< where the stroke lifts, cells
  int window_xy = 0;       ///< active window X and Y, cells (0: the scene's)
  SimCounters* counters = nullptr;  ///< receives the simulator's counters after the stroke
  bool travel_back = false;  ///< after the lift, the lifted brush goes back to the start in one step
};

/// Power of the spectrum of v[i0, i0 + n) at bin k, after removing its least-squares quadratic
/// trend (the load running down).
double detrended_power(const std::vector<double>& v, int i0, int n, int k) {
  double S[5] = {0, 0, 0, 0, 0}, B[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * (i + 0.5) / n - 1.0, y = v[size_t(i0 + i)];
    for (int q = 0; q < 5; ++q) S[q] += std::pow(t, q);
    for (int q = 0; q < 3; ++q) B[q] += y * std::pow(t, q);
  }
  const double M[3][3] = {{S[0], S[1], S[2]}, {S[1], S[2], S[3]}, {S[2], S[3], S[4]}};
  auto det3 = [](const double A[3][3]) {
    return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
           A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  };
  double c[3];
  for (int q = 0; q < 3; ++q) {  // Cramer's rule
    double A[3][3];
    for (int r = 0; r < 3; ++r)
      for (int j = 0; j < 3; ++j) A[r][j] = j == q ? B[r] : M[r][j];
    c[q] = det3(A) / det3(M);
  }
  double re = 0, im = 0;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * (i + 0.5) / n - 1.0;
    const double r = v[size_t(i0 + i)] - (c[0] + c[1] * t + c[2] * t * t);
    re += r * std::cos(2 * M_PI * k * i / n), im -= r * std::sin(2 * M_PI * k * i / n);
  }
  return re * re + im * im;
}

/// Power at bin k over the mean of bins k +- 2..5 (a peak stands out of its neighbours).
double peak_ratio(const std::vector<double>& v, int i0, int n, int k) {
  double neighbours = 0;
  int count = 0;
  for (int j = k - 5; j <= k + 5; ++j)
    if (std::abs(j - k) >= 2) neighbours += detrended_power(v, i0, n, j), ++count;
  return detrended_power(v, i0, n, k) / (neighbours / count);
}

/// The pen of a broadside pull along x at y0: tilted 20 degrees, twisted 90 (a flat's width
/// across the stroke); a pose from (x, pressure, down).
auto broadside_pen(const BrushSpec& brush, float y0) {
  return [&brush, y0](float x, float p, bool down) {
    PenSample s;
    s.x = x, s.y = y0, s.pressure = p, s.tilt_x = 20.f, s.twist = 90.f, s.down = down;
    return pose_from_pen(s, brush);
  };
}

/// Presses `pose` (x, pressure, down) at xa in `steps` steps, pulls it to xb at `speed` cells/s
/// in sub-steps of at most 2 cells, and lifts it there for as many steps.
template <class Pose>
void pull_broadside(Simulator& sim, const Pose& pose, float xa, float xb, float speed, float pressure, int steps) {
  for (int i = 1; i <= steps; ++i) sim.step(pose(xa, pressure * float(i) / float(steps), true), kDt);
  const int substeps = int(std::ceil(speed * kDt / 2.f));
  std::vector<BrushPose> poses(static_cast<size_t>(substeps));
  for (float x = xa; x < xb; x += speed * kDt) {
    for (int k = 0; k < substeps; ++k)
      poses[size_t(k)] = pose(std::min(xb, x + speed * kDt * float(k + 1) / float(substeps)), pressure, true);
    sim.step(poses.data(), substeps, kDt);
  }
  for (int i = 0; i < steps; ++i) sim.step(pose(xb, 0.f, false), kDt);
}

/// A broadside stroke's thickness map and body (StrokePropertiesTest::flat_broadside).
struct BroadsideStroke {
  static constexpr int W = 640, H = 128;
  std::vector<double> h;       ///< W * H, index y * W + x
  std::vector<double> across;  ///< mean thickness of each row over the body's columns
  int x0 = 0, x1 = 0, ya = H, yb = -1;
  double peak = 0;
  double at(int x, int y) const { return h[size_t(y) * W + x]; }
};

class StrokePropertiesTest : public SimulatorTest {
 protected:
  /// A small flat (a fifth of the default flat's 12 mm): 60 bristles of 0.25 cells, 6 mm long,
  /// 3.2 mm wide.
  static BrushSpec small_flat() {
    BrushSpec b = default_brush(BrushShape::Flat);
    b.bristles = 60;
    b.bristle_radius = 0.25f;
    b.length = 30.f;
    b.width = 16.f;
    b.thickness = 4.f;
    b.samples_per_bristle = 48;
    return b;
  }

  /// Column paint (cells) per canvas column after `st`; `sim_out` receives the canvas if set.
  std::vector<float> paint_stroke(const Stroke& st) {
    SimConfig c = small_config(CanvasDims{kW, kH, 16});
    if (st.window_xy > 0) c.window = Int3{st.window_xy, st.window_xy, c.window.z};
    if (st.brush) c.brush = *st.brush;
    c.particles = st.particles;
    auto pose = [&](float x, float p, bool down = true) {
      PenSample s;
      s.x = x, s.y = st.y, s.pressure = p, s.twist = st.twist, s.down = down;
      return pose_from_pen(s, c.brush);
    };
    Simulator sim(c, pose(kX0, 0.f, false));
    PaintLoad paint = red();
    paint.load = st.load;
    sim.load_paint(paint);
    const float dt = st.dt;
    const int land = int(std::lround(4.f * kDt / dt)), lift = int(std::lround(6.f * kDt / dt));
    for (int i = 1; i <= land; ++i) sim.step(pose(kX0, st.pressure * float(i) / float(land)), dt);
    const int substeps = std::max(1, int(std::ceil(st.speed * dt / st.max_move)));
    std::vector<BrushPose> poses(static_cast<size_t>(substeps), pose(kX0, st.pressure));
    float x = kX0;
    while (x < st.end) {
      // Eased: v = speed sqrt(d / ease) over the first `ease` cells, a constant acceleration.
      const float v = st.ease > 0.f ? st.speed * std::sqrt(std::min(1.f, (x - kX0 + 0.05f) / st.ease)) : st.speed;
      for (int k = 0; k < substeps; ++k)
        poses[size_t(k)] = pose(std::min(st.end, x + v * dt * float(k + 1) / float(substeps)), st.pressure);
      sim.step(poses.data(), substeps, dt);
      x += v * dt;
    }
    for (int i = 0; i < lift; ++i) sim.step(pose(st.end, 0.f, false), dt);
    if (st.travel_back) {
      // Lifted all the way, a sub-step a brush length (StrokePlayer::lifted_move_limit).
      const int n = int(std::ceil((st.end - kX0) / c.brush.length));
      std::vector<BrushPose> back;
      for (int k = 1; k <= n; ++k) back.push_back(pose(st.end + (kX0 - st.end) * float(k) / float(n), 0.f, false));
      sim.step(back.data(), n, dt);
      for (int i = 0; i < lift; ++i) sim.step(pose(kX0, 0.f, false), dt);
    }
    if (std::getenv("WB_STROKE_TOTALS")) {
      const TransferTotals& t = sim.books().totals();
      std::printf("dt %.4f: emitted %.4g kg (%lld), absorbed %.4g (%lld), to_grid %.4g, to_particles %.4g, bristles left %.4g\n",
                  dt, t.emitted, (long long)t.emitted_count, t.absorbed, (long long)t.absorbed_count, t.to_grid, t.to_particles,
                  sim.census().bristles);
    }
    if (st.counters) *st.counters = sim.counters();
    sim.settle();
    if (std::getenv("WB_STROKE_BOOKS")) {
      const PaintCensus cs = sim.census();
      std::printf("books: expected %.4g kg, census %.4g (bristles %.3g, particles %.3g, grid %.3g), canvas %.1f cells\n",
                  sim.books().expected_total(), cs.total(), cs.bristles, cs.particles, cs.grid,
                  sim.canvas().total_density());
    }
    EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
    EXPECT_EQ(sim.counters().nonfinite_events, 0);
    PaintWindow w(device_, Int3{kW, kH, 16});
    SimulatorTestAccess::canvas(sim).gather(w);
    const auto host = w.to_host();
    std::vector<float> col(size_t(kW) * kH, 0.f);
    for (int z = 0; z < 16; ++z)
      for (int y = 0; y < kH; ++y)
        for (int xx = 0; xx < kW; ++xx) col[size_t(y) * kW + xx] += host[0][(size_t(z) * kH + y) * kW + xx];
    if (const char* dir = std::getenv("WB_STROKE_DUMP")) {  // column paint as an 8-bit PGM, 40 levels a cell
      static int serial = 0;
      const std::string name = std::string(dir) + "/stroke_" + std::to_string(serial++) + ".pgm";
      if (FILE* f = std::fopen(name.c_str(), "wb")) {
        std::fprintf(f, "P5 %d %d 255\n", kW, kH);
        for (float v : col) std::fputc(int(std::min(255.f, v * 40.f)), f);
        std::fclose(f);
      }
    }
    return col;
  }
  /// The paint's thickness per canvas column (cells) after the default flat brush full of thick
  /// paint (oil 0.1) is pulled `length` cells broadside at 60 mm/s at half pressure, in a window
  /// that holds it with its particle zone; and the stroke's body: the middle 60 % of its length,
  /// the rows whose mean thickness over it is over 30 % of the thickest row's.
  BroadsideStroke flat_broadside(float length, bool particles) {
    using S = BroadsideStroke;
    constexpr float y0 = 64.f, xa = 70.f, speed = 300.f, pressure = 0.5f;
    const float xb = xa + length;
    SimConfig c = small_config(CanvasDims{S::W, S::H, 32});
    c.brush = default_brush(BrushShape::Flat);
    c.window = Int3{160, 160, 32};
    c.params.particles = ParticleParams{};  // the scene's small-brush D0 and D1 are not this brush's
    c.particles = particles;
    const auto pose = broadside_pen(c.brush, y0);
    Simulator sim(c, pose(xa, 0.f, false));
    PaintLoad paint = red();
    paint.oil = 0.1f;
    sim.load_paint(paint);
    pull_broadside(sim, pose, xa, xb, speed, pressure, 8);
    sim.settle();
    EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
    EXPECT_EQ(sim.counters().nonfinite_events, 0);
    EXPECT_EQ(sim.counters().zone_cut_steps, 0);
    PaintWindow w(device_, Int3{S::W, S::H, 32});
    SimulatorTestAccess::canvas(sim).gather(w);
    const auto f = w.to_host();
    S st;
    st.h.assign(size_t(S::W) * S::H, 0.0);
    for (int z = 0; z < 32; ++z)
      for (size_t id = 0; id < st.h.size(); ++id) st.h[id] += f[0][size_t(z) * st.h.size() + id];
    st.x0 = int(xa + 0.2f * length), st.x1 = int(xa + 0.8f * length);
    st.across.assign(S::H, 0.0);
    for (int y = 0; y < S::H; ++y)
      for (int x = st.x0; x < st.x1; ++x) st.across[size_t(y)] += st.at(x, y) / double(st.x1 - st.x0);
    st.peak = *std::max_element(st.across.begin(), st.across.end());
    for (int y = 0; y < S::H; ++y)
      if (st.across[size_t(y)] > 0.3 * st.peak) st.ya = std::min(st.ya, y), st.yb = std::max(st.yb, y);
    return st;
  }
  std::vector<float> paint_stroke(float speed, float max_move) {
    Stroke st;
    st.speed = speed, st.max_move = max_move;
    return paint_stroke(st);
  }
  /// Paint per cell of track (cells^2) at each column x: the column paint summed across y.
  static std::vector<double> per_length(const std::vector<float>& col) {
    std::vector<double> v(kW, 0.0);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) v[size_t(x)] += col[size_t(y) * kW + x];
    return v;
  }
  /// Share of the cells of rows [y0, y1] and columns [x0, x1) holding at least a tenth of a
  /// cell of paint.
  static double coverage(const std::vector<float>& col, int x0 = kBody0, int x1 = kBody1, int y0 = int(kY) - 3,
                         int y1 = int(kY) + 3) {
    int n = 0, covered = 0;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x < x1; ++x, ++n) covered += col[size_t(y) * kW + x] >= 0.1f;
    return double(covered) / n;
  }
};

TEST_F(StrokePropertiesTest, SameStrokeWithMoreOrFewerSubstepsPaintsTheSame) {
  // 160 mm/s, sub-steps of at most 1 cell, the stroke format's default (3 cells, what a replay
  // and the studio take) and 4 cells (14, 5 and 4 sub-steps a step). The other tests here take
  // 2-cell sub-steps, in the middle.
  const std::vector<float> a = paint_stroke(800.f, 1.f), b = paint_stroke(800.f, wb::Stroke{}.max_move_per_substep),
                           c = paint_stroke(800.f, 4.f);
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
  std::printf("paint on the canvas: %.1f, %.1f, %.1f cells; block L1 to the default: %.3f, %.3f\n", total(a), total(b),
              total(c), l1(b, a), l1(b, c));
  EXPECT_NEAR(total(a), total(b), 0.1 * total(b));
  EXPECT_NEAR(total(c), total(b), 0.1 * total(b));
  EXPECT_LT(l1(b, a), 0.3);
  EXPECT_LT(l1(b, c), 0.3);
  EXPECT_GE(coverage(b), 0.9) << "a continuous layer along the track at 160 mm/s";
}

TEST_F(StrokePropertiesTest, SameStrokeWithHalfTheTimeStepPaintsTheSame) {
  // 160 mm/s, sub-steps of at most 2 cells, steps of 1/60 s and 1/120 s: the grid's viscous solve,
  // projection and advection, the particles and the transfer all run twice as often.
  Stroke coarse, fine;
  fine.dt = 0.5f * kDt;
  const std::vector<float> a = paint_stroke(coarse), b = paint_stroke(fine);
  double ta = 0, tb = 0, d = 0;
  for (float x : a) ta += x;
  for (float x : b) tb += x;
  for (int by = 0; by < kH; by += 4)  // L1 per 4 x 4-cell block, as for the sub-steps
    for (int bx = 0; bx < kW; bx += 4) {
      double sa = 0, sb = 0;
      for (int y = by; y < by + 4; ++y)
        for (int x = bx; x < bx + 4; ++x) sa += a[size_t(y) * kW + x], sb += b[size_t(y) * kW + x];
      d += std::fabs(sa - sb);
    }
  std::printf("dt 1/60 s: %.1f cells of paint, coverage %.0f %%; dt 1/120 s: %.1f, %.0f %%; block L1 %.3f\n", ta,
              100 * coverage(a), tb, 100 * coverage(b), d / ta);
  // Tolerance: 15 % of the paint and block L1 0.35. Measured: +12.4 % of paint and L1 0.297 at the
  // finer step; the per-step emit and absorb limits are not the cause (64 and 1024 give +10.8 %).
  // The remaining step-size dependence is open (docs/TRANSFER.md "Step size").
  EXPECT_NEAR(tb, ta, 0.15 * ta);
  EXPECT_LT(d / ta, 0.35);
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

TEST_F(StrokePropertiesTest, AFlickLaysPaintAlongItsWholePath) {
  // 2 m/s (10 000 cells/s): the brush sweeps 167 cells a step, more than three times the
  // 48-cell window. Laid only where the window stood, the paint came in window-wide blocks with
  // hard edges and gaps between them; each part of a split step now places the window anew
  // (Simulator::step, docs/GRID.md "Flicks").
  SimCounters counters;
  Stroke st;
  st.speed = 10000.f;
  st.max_move = 3.f;
  st.counters = &counters;
  const std::vector<float> col = paint_stroke(st);
  const std::vector<double> v = per_length(col);
  const double cover = coverage(col);
  // The largest change of the paint per unit length from one column to the next, against the
  // body's median: a window's edge is a step as deep as the stroke.
  std::vector<double> body(v.begin() + kBody0, v.begin() + kBody1), jumps;
  for (int x = kBody0; x + 1 < kBody1; ++x) jumps.push_back(std::fabs(v[size_t(x) + 1] - v[size_t(x)]));
  std::nth_element(body.begin(), body.begin() + body.size() / 2, body.end());
  const auto top = std::max_element(jumps.begin(), jumps.end());
  const double median = body[body.size() / 2], worst = *top;
  std::printf("flick at 2 m/s: coverage %.1f %%, paint per cell of track: median %.2f, largest change between "
              "columns %.2f (at x %d); %lld of %lld steps in %lld parts\n",
              100 * cover, median, worst, kBody0 + int(top - jumps.begin()), (long long)counters.split_steps, (long long)counters.steps,
              (long long)counters.step_parts);
  EXPECT_GT(counters.split_steps, 0);
  EXPECT_GE(cover, 0.95) << "the whole path is painted";
  // A window's edge is a step as deep as the stroke (442 with window-wide blocks). The parts of
  // the split step join at x 79 and 103 with steps of 0.33-0.51 of the median over runs: less
  // than the stroke's own relief (the bound), not nothing (docs/GRID.md "Flicks").
  EXPECT_LT(worst, 0.6 * median) << "no edge where a window stood";
}

TEST_F(StrokePropertiesTest, ConstantSpeedLeavesNoStepPattern) {
  // 60 mm/s: a step moves the brush 5 cells, so a deposit made per step would repeat every 5
  // cells along the track. Over the 80-cell body that is bin 16 of the spectrum of the paint
  // per unit length (its slow trend, the load running down, removed by a quadratic fit).
  Stroke st;
  st.speed = 300.f;
  const std::vector<double> v = per_length(paint_stroke(st));
  const int n = kBody1 - kBody0;
  const int step_bin = int(std::lround(n / (st.speed * kDt)));
  const double ratio = peak_ratio(v, kBody0, n, step_bin);
  std::printf("spectrum of the paint per unit length: step bin %d, power over its neighbours' mean %.2f\n", step_bin,
              ratio);
  // One bead a step (every sample's swept particle at the middle of its path) gave ratios of
  // 6.5 to 25; stratified along the path, 1.9 to 3.5 over runs.
  EXPECT_LT(ratio, 4.0) << "a peak at the step period";
}

/// The strongest peak of the spectrum of the thickness along the track over [x0, x0 + n), periods
/// 2 to 20 cells, over the continuum at its period: each of the track's 11 central rows of each
/// body detrended and transformed, their powers averaged (ribs run across the rows and recur in
/// every body painted by the same stroke; texture recurs less, the second body lying half a cell
/// across; Bartlett's average), then each
/// bin's power over the median of the 8 bins nearest it (itself left out). A rib is a line above
/// its neighbours; the body's texture is a continuum, red where the paint is smooth (surface
/// tension levels the shortest periods first), and a peak over the median of all the bins
/// would measure how red it is: a smooth body's longer periods stand over its median whatever
/// their shape. The peak's period goes to `period`, and the same ratio at `at_period` cells to `at`.
double rib_peak(const std::vector<std::vector<float>>& bodies, int x0, int n, int* period = nullptr,
                int at_period = 0, double* at = nullptr, double* amplitude = nullptr) {
  const int k0 = (n + 19) / 20, bins = n / 2 - k0 + 1;
  std::vector<double> power(size_t(bins), 0.0);
  const double rows = 11.0 * double(bodies.size());
  for (const std::vector<float>& col : bodies)
    for (int y = int(kY) - 5; y <= int(kY) + 5; ++y) {
      std::vector<double> v(kW, 0.0);
      for (int x = 0; x < kW; ++x) v[size_t(x)] = col[size_t(y) * kW + x];
      for (int b = 0; b < bins; ++b) power[size_t(b)] += detrended_power(v, x0, n, k0 + b) / rows;
    }
  // Bin b over the median of its 8 nearest others (at the range's ends, those on its one side).
  const auto over_continuum = [&](int b) {
    std::vector<double> near;
    for (int d = 1; near.size() < 8 && d < bins; ++d) {
      if (b - d >= 0) near.push_back(power[size_t(b - d)]);
      if (near.size() < 8 && b + d < bins) near.push_back(power[size_t(b + d)]);
    }
    std::sort(near.begin(), near.end());
    return power[size_t(b)] / (0.5 * (near[near.size() / 2 - 1] + near[near.size() / 2]));
  };
  int top = 0;
  double best = 0.0;
  for (int b = 0; b < bins; ++b)
    if (const double r = over_continuum(b); r > best) best = r, top = b;
  // A sinusoid a sin(2 pi k i / n) has |F_k| = a n / 2: the peak's amplitude in cells.
  if (amplitude) *amplitude = 2.0 * std::sqrt(power[size_t(top)]) / double(n);
  if (period) *period = int(std::lround(double(n) / double(k0 + top)));
  if (at) *at = at_period > 0 ? over_continuum(n / at_period - k0) : 0.0;
  return best;
}

// The rib measure on bodies made up: a load running down (the quadratic trend) with a texture of
// +-0.03 cells and no period: no peak stands out (ratio at most 5) or none a raking light shows
// (slope at most 0.03); the same with ridges of 0.2 cells every 10 cells (the ribs that were) or of
// 0.05 every 6: both.
TEST(RibMeasure, FlagsRidgesARakingLightShowsOnly) {
  std::mt19937 rng(7);
  std::normal_distribution<float> texture(0.f, 0.03f);
  const auto body = [&](float ridge, int period) {
    std::vector<float> col(size_t(kW) * kH, 0.f);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const float u = float(x - kBody0) / 64.f;
        col[size_t(y) * kW + x] = 1.8f - 0.9f * u + 0.2f * u * u + texture(rng) +
                                  ridge * std::sin(2.f * float(M_PI) * float(x) / float(period));
      }
    return col;
  };
  const auto rib = [&](float ridge, int period, double* slope) {
    double amplitude = 0.0;
    int at = 0;
    const double ratio = rib_peak({body(ridge, period)}, kBody0, 64, &at, 0, nullptr, &amplitude);
    *slope = 2.0 * M_PI * amplitude / double(at);
    return ratio;
  };
  double slope = 0.0;
  const double smooth = rib(0.f, 10, &slope);
  EXPECT_TRUE(smooth <= 4.0 || slope <= 0.03) << smooth << "x, slope " << slope;
  EXPECT_GT(rib(0.2f, 10, &slope), 4.0);
  EXPECT_GT(slope, 0.06);
  EXPECT_GT(rib(0.05f, 6, &slope), 4.0);
  EXPECT_GT(slope, 0.03);
}

TEST_F(StrokePropertiesTest, SlowAndEasedStrokesLeaveNoRibs) {
  // Ribs: ridges across the track a few cells apart where the brush is slow (docs/TRANSFER.md
  // "Ribs on slow strokes", docs/GRID.md "The window's walls"). At 5, 15 and 40 mm/s and from
  // rest, round and flat (broadside), in a window the particle zone fits: the strongest peak of
  // the body's thickness spectrum, periods 2-20 cells, over the continuum at its period (rib_peak),
  // each stroke painted twice, the second half a cell across, and the same ratio at the distance
  // blocks' period (4 cells), where the D0 front's steps laid ridges on a lattice held by the
  // window. A peak is a rib where it stands over 4x the continuum (the bound) *and* a
  // raking light shows it: its slope, 2 pi amplitude / period, over 0.03 (light 15 degrees above
  // the canvas: the shading rises and falls by a tenth). The ribs that were: 0.2 cells every 10
  // cells, a slope of 0.13. The brush lifts past the body by its length: its trailing bristles,
  // pressed and raised at the lift, put a step into the body's last cells with the lift 16 cells
  // past it. The flat broadside at 15 mm/s laid a line at the 2-cell period (up to 5.3x) while the
  // swept deposit's pattern slots cycled with the step (pattern_slot, docs/TRANSFER.md "Ribs on
  // slow strokes").
  constexpr double kVisibleSlope = 0.03;
  struct Case {
    const char* name;
    float speed, ease;
    bool flat;
  };
  constexpr double kMost = 4.0;  // the bound
  const Case cases[] = {{"round 5 mm/s", 25.f, 0.f, false},   {"round 15 mm/s", 75.f, 0.f, false},
                        {"round 40 mm/s", 200.f, 0.f, false}, {"round eased", 300.f, 80.f, false},
                        {"flat 5 mm/s", 25.f, 0.f, true},     {"flat 15 mm/s", 75.f, 0.f, true},
                        {"flat 40 mm/s", 200.f, 0.f, true},   {"flat eased", 300.f, 80.f, true}};
  for (const Case& k : cases) {
    // The eased stroke's body is where it speeds up (past the landing's first 16 cells, where
    // its thickness falls steeper than the detrending's quadratic); the others' past the landing.
    const int x0 = k.ease > 0.f ? int(kX0) + 16 : kBody0, n = 64;
    Stroke st;
    st.speed = k.speed, st.ease = k.ease, st.window_xy = 96;
    if (k.flat) st.brush = small_flat(), st.twist = 90.f;
    st.end = float(x0 + n) + (st.brush ? st.brush->length : small_config().brush.length);
    std::vector<std::vector<float>> bodies{paint_stroke(st)};
    st.y = kY + 0.5f;
    bodies.push_back(paint_stroke(st));
    int period = 0;
    double at_block = 0.0, amplitude = 0.0;
    const int block = TransferParams{}.distance_block;
    const double ratio = rib_peak(bodies, x0, n, &period, block, &at_block, &amplitude);
    const double slope = 2.0 * M_PI * amplitude / double(period);
    std::printf("%-14s strongest peak of periods 2-20 cells: %.1fx the continuum, at %d cells, amplitude %.3f cells "
                "(slope %.3f); at the distance blocks' %d cells %.1fx\n",
                k.name, ratio, period, amplitude, slope, block, at_block);
    EXPECT_TRUE(ratio <= kMost || slope <= kVisibleSlope)
        << k.name << ": a peak " << ratio << "x the continuum at " << period << " cells, " << amplitude
        << " cells high";
    EXPECT_LE(at_block, 3.0) << k.name << ": ridges at the distance blocks' period";
  }
}

TEST_F(StrokePropertiesTest, WindowMovesReturnNoParticlesWhereTheParticleZoneFits) {
  // The window follows the brush in moves of window_snap cells. Where the particle zone reached
  // past the window's kept box, each move returned the strip of particles it left to the grid at
  // once, not by Eq. 16 behind the brush: on a flat brush in stiff paint, a band across the
  // stroke every 8 cells (docs/TRANSFER.md "The particle zone"). In a window that holds the brush
  // and its zone, the zone is never cut and moves return (almost) no particles; in the scene's
  // 48-cell window it is cut, and the moves return particles by the thousand.
  Stroke st;
  st.speed = 300.f;
  SimCounters fit, cut;
  st.counters = &fit;
  st.window_xy = 128;
  const std::vector<double> v = per_length(paint_stroke(st));
  st.counters = &cut;
  st.window_xy = 0;
  paint_stroke(st);
  std::printf("particles returned at window moves: %lld in a 128-cell window (zone cut on %lld of %lld steps), "
              "%lld in the 48-cell window (cut on %lld)\n",
              (long long)fit.returned_at_moves, (long long)fit.zone_cut_steps, (long long)fit.steps,
              (long long)cut.returned_at_moves, (long long)cut.zone_cut_steps);
  EXPECT_EQ(fit.zone_cut_steps, 0) << "the 128-cell window holds the small brush and its zone";
  // The lifted brush's travel back over the stroke spans more than the window: it goes in parts,
  // and its zone, on paper cut, returns nothing at the moves (no warning names a larger window).
  SimCounters back;
  st.counters = &back;
  st.window_xy = 128;
  st.travel_back = true;
  paint_stroke(st);
  EXPECT_GT(back.split_steps, 0) << "the travel takes more than the window";
  EXPECT_EQ(back.zone_cut_steps, 0) << "a lifted brush's travel cuts no zone that shows";
  EXPECT_GT(cut.zone_cut_steps, 0);
  EXPECT_LE(cut.zone_cut_steps, cut.steps) << "only steps count (the first placement is not one)";
  // A twentieth at most: the fit window's returns vary from run to run with the order of the
  // threads' atomic sums, 954-1137 against 37.5-37.8 K (2.5-3.0 %).
  EXPECT_LT(double(fit.returned_at_moves), 0.05 * double(std::max<int64_t>(cut.returned_at_moves, 1)));
  const int n = kBody1 - kBody0, snap = small_config().params.grid.window_snap;
  EXPECT_LT(peak_ratio(v, kBody0, n, n / snap), 4.0) << "a peak at the window snap's period";
}

TEST_F(StrokePropertiesTest, OneLoadRunsOutAlongALongStroke) {
  // The small flat (a fifth of the default flat) with a third of a full load, pulled broadside
  // over the whole 34 mm track at 120 mm/s: the load runs down along the stroke, and its end
  // breaks into dry-brush coverage. Measured: last quarter 48 % of the first, 84 % covered.
  Stroke st;
  st.speed = 600.f;
  st.brush = small_flat();
  st.twist = 90.f;
  st.load = 0.3f;
  const std::vector<float> col = paint_stroke(st);
  const std::vector<double> v = per_length(col);
  const int q = (int(kX1) - int(kX0)) / 4;
  double first = 0, last = 0;
  for (int x = int(kX0); x < int(kX0) + q; ++x) first += v[size_t(x)];
  for (int x = int(kX1) - q; x < int(kX1); ++x) last += v[size_t(x)];
  const double end_cover = coverage(col, int(kX1) - q, int(kX1), int(kY) - 5, int(kY) + 5);
  std::printf("paint per unit length: first quarter %.2f, last quarter %.2f cells^2 (%.0f %%); last quarter covered %.0f %%\n",
              first / q, last / q, 100 * last / first, 100 * end_cover);
  EXPECT_LT(last, 0.6 * first) << "the load runs down";
  EXPECT_LT(end_cover, 0.9) << "the end breaks into dry-brush coverage";
  EXPECT_GT(last, 0.0) << "but still paints";
}

TEST_F(StrokePropertiesTest, APressedBrushRollingSlowlyKeepsTheFilmInWholeParticles) {
  // The default flat, full, pressed (0.8) into the canvas and held for 20 steps, then rolled and
  // dragged slowly (30 mm/s) for 40: its bristles rest on and slide over the film they laid. The
  // particles stay about the size they were made (emitted: emit_mass, an eighth of a cell;
  // Eq. 15's candidates: a 1/27 share of a full cell): a touching sample takes a film particle
  // whole or not at all, and a thin cell near the bristles becomes one candidate, not 27
  // (docs/TRANSFER.md "Swept contact", "Candidates"). Measured at the most particles: 432 000, 38 %
  // of them lighter than 1/64 of a cell, when a touching sample took half of every particle it
  // rested on each step and every cell became 27; 209 000 and 5.1 % now.
  SimConfig c = small_config(CanvasDims{kW, 160, 32});
  c.brush = default_brush(BrushShape::Flat);
  c.window = Int3{128, 128, 32};
  c.params.particles = ParticleParams{};  // the scene's small-brush D0 and D1 are not this brush's
  auto pose = [&](float x, float p, float twist, bool down = true) {
    PenSample s;
    s.x = x, s.y = 80.f, s.pressure = p, s.twist = twist, s.down = down;
    return pose_from_pen(s, c.brush);
  };
  Simulator sim(c, pose(kX0, 0.f, 0.f, false));
  sim.load_paint(red());
  const float speck = c.params.transfer.cell_mass() / 64.f;
  int64_t most = 0, specks_then = 0;
  const auto count = [&] {
    const std::vector<float> m = sim.particles().m.to_host();
    const int64_t n = sim.particle_count();  // the live ones lead the store: compacted each step
    int64_t light = 0;
    for (int64_t k = 0; k < n; ++k) light += m[size_t(k)] < speck;
    if (n > most) most = n, specks_then = light;
  };
  for (int i = 1; i <= 4; ++i) sim.step(pose(kX0, 0.2f * float(i), 0.f), kDt);
  for (int i = 0; i < 20; ++i) sim.step(pose(kX0, 0.8f, 0.f), kDt), count();
  for (int i = 1; i <= 40; ++i) sim.step(pose(kX0 + 2.5f * float(i), 0.8f, 3.f * float(i)), kDt), count();
  std::printf("at the most %lld particles, %lld (%.1f %%) lighter than 1/64 of a cell\n", (long long)most,
              (long long)specks_then, 100.0 * double(specks_then) / double(std::max<int64_t>(most, 1)));
  ASSERT_GT(most, 1000) << "the brush lays its film as particles";
  EXPECT_LT(double(specks_then), 0.1 * double(most));
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
}

TEST_F(StrokePropertiesTest, FlatPulledBroadsideLeavesBristleStreaks) {
  // 100 mm (500 cells). In the stroke's body the paint's thickness varies across the stroke (the
  // bristles' tracks) far more than along it, in distinct ridges (docs/TRANSFER.md "Bristle
  // streaks").
  const BroadsideStroke st = flat_broadside(500.f, true);
  const int ya = st.ya, yb = st.yb;
  ASSERT_LT(ya, yb) << "no stroke body";
  double d_across = 0, d_along = 0;
  int n = 0;
  for (int y = ya; y < yb; ++y)
    for (int x = st.x0; x < st.x1; ++x, ++n) {
      const double v = st.at(x, y);
      d_along += std::abs(st.at(x + 1, y) - v);
      d_across += std::abs(st.at(x, y + 1) - v);
    }
  d_across /= n, d_along /= n;
  // Ridges: maxima of the along-averaged profile standing 0.05 cells over the lower of their
  // neighbourhoods' minima (4 rows each side).
  const std::vector<double>& across = st.across;
  int ridges = 0;
  for (int y = ya + 1; y < yb; ++y) {
    const double v = across[size_t(y)];
    if (!(v > across[size_t(y - 1)] && v >= across[size_t(y + 1)])) continue;
    double lo_l = v, lo_r = v;
    for (int k = 1; k <= 4; ++k) {
      lo_l = std::min(lo_l, across[size_t(std::max(ya, y - k))]);
      lo_r = std::min(lo_r, across[size_t(std::min(yb, y + k))]);
    }
    ridges += v - std::max(lo_l, lo_r) >= 0.05;
  }
  std::printf("flat broadside, 100 mm at 60 mm/s: body rows %d-%d, mean |dh/dacross| %.3f, |dh/dalong| %.3f "
              "(ratio %.2f), %d ridges across, mean thickness %.2f cells\n",
              ya, yb, d_across, d_along, d_across / d_along, ridges, st.peak);
  EXPECT_GE(d_across, 2.0 * d_along) << "bristle streaks: the paint varies across the stroke";
  EXPECT_GE(ridges, 4) << "distinct ridges across the stroke";
}

/// The grooves of a thin broadside layer: the small flat pulled broadside, 16 mm at 60 mm/s,
/// in paint of `oil`, lifted over the stroke's end and left `rest` seconds in a window holding
/// the whole canvas. The depth is the RMS of the across-stroke profile (the body's columns
/// averaged) less its 5-row running mean, over the rows of the body; at the lift and after.
struct Grooves {
  double before = 0, after = 0;                ///< the grooves along the stroke, cells RMS
  double ridges_before = 0, ridges_after = 0;  ///< the ridges across it (the along profile's), cells RMS
  double thickness = 0;                        ///< the body's mean, cells
};

/// RMS of v[i0, i1) less its local quadratic (the 5-sample least-squares fit about each sample,
/// Savitzky-Golay): grooves and ridges a few cells apart stand out, a stroke's rounded section
/// or a slow swell does not (a running mean counts the curvature of a smooth dome).
double high_pass_rms(const std::vector<double>& v, int i0, int i1) {
  constexpr double w[5] = {-3.0 / 35, 12.0 / 35, 17.0 / 35, 12.0 / 35, -3.0 / 35};
  double sq = 0;
  for (int i = i0; i < i1; ++i) {
    double fit = 0;
    for (int k = -2; k <= 2; ++k) fit += w[k + 2] * v[size_t(i + k)];
    sq += (v[size_t(i)] - fit) * (v[size_t(i)] - fit);
  }
  return i1 > i0 ? std::sqrt(sq / (i1 - i0)) : 0.0;
}

Grooves broadside_grooves_at_rest(const Device& device, const SimConfig& scene, BrushSpec brush, float oil, float rest) {
  constexpr int W = 128, H = 64;
  constexpr float y0 = 32.f, xa = 24.f, xb = 104.f, speed = 300.f, pressure = 0.5f;
  SimConfig c = scene;
  c.canvas = CanvasDims{W, H, 16};
  c.window = Int3{W, H, 16};
  c.brush = brush;
  const auto pose = broadside_pen(c.brush, y0);
  Simulator sim(c, pose(xa, 0.f, false));
  PaintLoad paint;
  paint.ryb[0] = 0.9f, paint.ryb[1] = 0.1f, paint.ryb[2] = 0.05f;
  paint.oil = oil;
  sim.load_paint(paint);
  pull_broadside(sim, pose, xa, xb, speed, pressure, 6);
  const BrushPose lifted = pose(xb, 0.f, false);
  // Grooves and ridges over the body: its middle half along, the rows over 30 % of the thickest.
  const int x0 = int(xa + 0.25f * (xb - xa)), x1 = int(xa + 0.75f * (xb - xa));
  const auto measure = [&](double& grooves, double& ridges, double* thickness) {
    sim.settle();  // the window's paint onto the canvas
    PaintWindow w(device, Int3{W, H, 16});
    SimulatorTestAccess::canvas(sim).gather(w);
    const auto f = w.to_host();
    std::vector<double> col(size_t(W) * H, 0.0), across(H, 0.0), along(W, 0.0);
    for (int z = 0; z < 16; ++z)
      for (size_t id = 0; id < col.size(); ++id) col[id] += f[0][size_t(z) * col.size() + id];
    for (int y = 0; y < H; ++y)
      for (int x = x0; x < x1; ++x) across[size_t(y)] += col[size_t(y) * W + x] / double(x1 - x0);
    const double peak = *std::max_element(across.begin(), across.end());
    int ya = H, yb = -1;
    for (int y = 0; y < H; ++y)
      if (across[size_t(y)] > 0.3 * peak) ya = std::min(ya, y), yb = std::max(yb, y);
    for (int y = ya; y <= yb; ++y)
      for (int x = 0; x < W; ++x) along[size_t(x)] += col[size_t(y) * W + x] / double(yb - ya + 1);
    grooves = high_pass_rms(across, ya + 2, yb - 1);
    ridges = high_pass_rms(along, x0, x1);
    if (thickness) {
      double mean = 0;
      for (int y = ya; y <= yb; ++y) mean += across[size_t(y)] / double(yb - ya + 1);
      *thickness = mean;
    }
  };
  Grooves g;
  measure(g.before, g.ridges_before, &g.thickness);
  for (int i = 0, n = int(std::lround(rest / kDt)); i < n; ++i) sim.step(lifted, kDt);
  measure(g.after, g.ridges_after, nullptr);
  EXPECT_LT(std::abs(sim.books().max_drift()), 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  std::printf("broadside in oil %.2f, body %.2f cells thick: grooves %.4f cells deep at the lift, %.4f after %.0f s at "
              "rest (%.1f %%); ridges across the track %.4f, %.4f\n", oil, g.thickness, g.before, g.after, rest,
              100.0 * g.after / g.before, g.ridges_before, g.ridges_after);
  return g;
}

TEST_F(StrokePropertiesTest, ThinOilyStrokeLevelsAtRestStiffKeepsItsGrooves) {
  // The levelling property on a painted stroke (docs/GRID.md "Thin films", "Surface tension"): a
  // layer about a cell thick, its bristle grooves a fraction of a cell deep. Surface tension
  // levels oily paint's grooves as the bristles lay them, so their depth is the one the same
  // stroke keeps with the films' flow off (the grid alone): what the bristles lay.
  SimConfig laid = small_config();
  laid.params.grid.film_max = 0.f;
  const Grooves bristles = broadside_grooves_at_rest(device_, laid, small_flat(), 0.95f, 0.f);
  const Grooves oily = broadside_grooves_at_rest(device_, small_config(), small_flat(), 0.95f, 2.f);
  EXPECT_GE(oily.thickness, 0.4);
  EXPECT_LE(oily.thickness, 2.0) << "a layer about one cell thick";
  EXPECT_GT(bristles.before, 0.01) << "the stroke lays grooves";
  EXPECT_LE(oily.after, 0.5 * bristles.before) << "oil-rich paint levels";
  EXPECT_LE(oily.ridges_after, 0.5 * bristles.ridges_before) << "and its ridges";
  const Grooves stiff = broadside_grooves_at_rest(device_, small_config(), small_flat(), 0.1f, 10.f);
  EXPECT_GT(stiff.before, 0.01);
  EXPECT_GE(stiff.after, 0.9 * stiff.before) << "stiff paint keeps its grooves";
  EXPECT_GE(stiff.ridges_after, 0.9 * stiff.ridges_before);
}

TEST_F(StrokePropertiesTest, HybridPaintKeepsMoreDetailThanGridOnly) {
  // Fig. 7a/b: the same 50 mm broadside stroke of the default flat with particles near the
  // bristles (the hybrid) and without (grid-only). Detail: the high-pass energy of the exported
  // thickness, its mean squared difference from the 3 x 3 mean, over the stroke's body.
  double energy[2], thickness[2];
  for (int mode = 0; mode < 2; ++mode) {
    const BroadsideStroke st = flat_broadside(250.f, mode == 0);
    ASSERT_LT(st.ya, st.yb) << "no stroke body";
    double e = 0;
    int n = 0;
    for (int y = st.ya; y <= st.yb; ++y)
      for (int x = st.x0; x < st.x1; ++x, ++n) {
        double mean = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) mean += st.at(x + dx, y + dy) / 9.0;
        e += (st.at(x, y) - mean) * (st.at(x, y) - mean);
      }
    energy[mode] = e / n, thickness[mode] = st.peak;
  }
  std::printf("high-pass energy of the thickness: hybrid %.5f, grid-only %.5f cells^2 (ratio %.2f); thickest row "
              "%.2f and %.2f cells\n",
              energy[0], energy[1], energy[0] / energy[1], thickness[0], thickness[1]);
  // Measured 0.0303 against 0.0077 (3.9).
  EXPECT_GE(energy[0], 2.0 * energy[1]) << "the hybrid keeps the bristles' detail";
}

TEST_F(StrokePropertiesTest, EveryShapeEdgeOnOrBroadsideLeavesAContinuousMark) {
  // At 120 mm/s with a full load: the round brush, and the small flat edge-on (4 cells across
  // the track) and broadside (16 cells across). Covered: the cells of the track's core, as wide
  // as the brush across it less its rims, through the stroke's body. Before samples sweeping
  // the same column in a step shared their deposit, the broadside flat laid its load in the
  // first steps and covered 70-82 %.
  struct Case {
    const char* name;
    bool flat;
    float twist;
    int half;  // half-width of the track's core, cells
  };
  for (const Case& k : {Case{"round", false, 0.f, 2}, Case{"flat edge-on", true, 0.f, 1},
                        Case{"flat broadside", true, 90.f, 6}}) {
    Stroke st;
    st.speed = 600.f;
    if (k.flat) st.brush = small_flat();
    st.twist = k.twist;
    const std::vector<float> col = paint_stroke(st);
    const double cover = coverage(col, kBody0, kBody1, int(kY) - k.half, int(kY) + k.half);
    std::printf("%s: core of the track covered %.0f %%\n", k.name, 100 * cover);
    EXPECT_GE(cover, 0.9) << k.name;
  }
}

}  // namespace
}  // namespace wb::test
