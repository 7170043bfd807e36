// Properties of a stroke over paint already on the canvas, measured on the paint the stroke
// leaves: a white brush drawn through wet red carries pink past it; a clean brush ploughs a wet
// layer. Small brush, short strokes (CI on two CPU cores).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <vector>

#include "core/render/renderer.h"
#include "core/render/test_volumes.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

constexpr float kDt = 1.f / 60.f;
constexpr int kDepth = 16;
constexpr float kY = 32.f;

// Diagnosis: WB_LAYER_VERBOSE=1 prints per-step figures (2: also by ridge phase) (where the paint is, what the bristles
// absorb and emit, where they touch); the WB_LAYER_* overrides below re-run a test with one
// parameter changed, to tell the causes of a failure apart.
int verbose() { return std::getenv("WB_LAYER_VERBOSE") ? std::atoi(std::getenv("WB_LAYER_VERBOSE")) : 0; }
float env_or(const char* name, float fallback) {
  const char* v = std::getenv(name);
  return v ? float(std::atof(v)) : fallback;
}

class LayerPropertiesTest : public SimulatorTest {
 protected:
  using CellFn = std::function<PaintCell(int x, int y, int z)>;

  SimConfig layer_config(CanvasDims canvas) const {
    SimConfig c = small_config(canvas);
    c.particles = env_or("WB_LAYER_PARTICLES", 1.f) != 0.f;
    c.brush.bristle_radius = env_or("WB_LAYER_BRISTLE_RADIUS", c.brush.bristle_radius);
    c.params.particles.delta = env_or("WB_LAYER_DELTA", c.params.particles.delta);
    c.params.particles.D1 = env_or("WB_LAYER_D1", c.params.particles.D1);
    c.params.particles.D0 = env_or("WB_LAYER_D0", c.params.particles.D0);
    c.params.grid.dry_threshold = env_or("WB_LAYER_DRY_THRESHOLD", c.params.grid.dry_threshold);
    c.params.transfer.absorb_limit = int(env_or("WB_LAYER_ABSORB_LIMIT", float(c.params.transfer.absorb_limit)));
    c.params.transfer.bleed = env_or("WB_LAYER_BLEED", c.params.transfer.bleed);
    return c;
  }

  /// Writes `cell` into every tile of the canvas (tiles left all empty are not allocated) and
  /// reloads the simulator's window from the canvas.
  static void write_layer(Simulator& sim, const CellFn& cell) {
    const CanvasDims d = sim.canvas().dims();
    fill_volume(SimulatorTestAccess::canvas(sim), 0, 0, d.width, d.height, cell);
    SimulatorTestAccess::grid(sim).window().reload();
  }

  /// The books from the census taken after the layer was written: the simulator opened its
  /// books on an empty canvas, so their own drift counts the layer as paint from nowhere.
  struct Books {
    double start = 0, external0 = 0;
    void open(Simulator& sim) {
      start = sim.census().total();
      external0 = sim.books().external_total();
    }
    /// Largest |census - expected| / expected over the steps recorded since open().
    double max_drift(const Simulator& sim) const {
      double ext = 0, worst = 0;
      for (const PaintStep& s : sim.books().steps()) {
        ext += s.external;
        const double expected = start + ext - external0;
        worst = std::max(worst, std::fabs(s.census.total() - expected) / expected);
      }
      return worst;
    }
  };

  /// A straight stroke along y = kY from x0 to x1 at `speed` cells/s (sub-steps of at most 2
  /// cells) at pen pressure `p`: the brush lands in 4 steps, drags, lifts in 6; then settle().
  static void drag(Simulator& sim, float x0, float x1, float speed, float p) {
    const BrushSpec& b = sim.config().brush;
    for (int i = 1; i <= 4; ++i) sim.step(pose_at(b, x0, kY, p * 0.25f * float(i)), kDt);
    const int substeps = std::max(1, int(std::ceil(speed * kDt / 2.f)));
    std::vector<BrushPose> poses(static_cast<size_t>(substeps));
    for (float x = x0; x < x1; x += speed * kDt) {
      for (int k = 0; k < substeps; ++k)
        poses[size_t(k)] = pose_at(b, std::min(x1, x + speed * kDt * float(k + 1) / float(substeps)), kY, p);
      sim.step(poses.data(), substeps, kDt);
      if (verbose()) {
        const PaintStep& st = sim.books().steps().back();
        int low = 0;
        float zmin = 1e9f;
        const auto xs = sim.brush().samples_to_host();
        for (const Vec3& q : xs) low += q.z < 4.f, zmin = std::min(zmin, q.z);
        std::vector<Vec3> px(size_t(sim.particles().size()));
        sim.particles().x.copy_to_host(px.data(), px.size());
        double pz = 0;
        for (const Vec3& q : px) pz += q.z;
        if (std::fabs(x - 0.5f * (x0 + x1)) < 0.5f * speed * kDt) {
          // Bristles as the grid sees them (psi, bristle volume per cell) in the paint's lowest
          // 4 cells: how much of the footprint is an obstacle.
          const Int3 o = sim.grid().window().origin(), n = sim.grid().window().dims();
          const size_t cells = size_t(n.x) * n.y * n.z;
          std::vector<float> psi(cells), vx(cells), vy(cells), vz(cells);
          SimulatorTestAccess::brush(sim).rasterize(o, n, psi.data(), vx.data(), vy.data(), vz.data());
          double sum = 0, peak = 0;
          int touched = 0, columns = 0;
          for (int y = 0; y < n.y; ++y)
            for (int xx = 0; xx < n.x; ++xx) {
              bool any = false;
              for (int z = 0; z < 4; ++z) {
                const float v = psi[(size_t(z) * n.y + y) * n.x + xx];
                sum += v, peak = std::max(peak, double(v)), touched += v > 0, any |= v > 0;
              }
              columns += any;
            }
          std::printf("  psi in z 0..4: %d cells touched, %d columns, sum %.2f cells, mean %.3f, peak %.3f\n", touched,
                      columns, sum, sum / std::max(touched, 1), peak);
        }
        if (verbose() >= 2) {
          // Over ridges across x (period 8, ridge x mod 8 < 4): particle mass by x mod 8 (0-3 over ridges) and high (z >= 3) or low; the
          // lowest sample of each bristle by x mod 8.
          std::vector<float> pm(size_t(sim.particles().size()));
          sim.particles().m.copy_to_host(pm.data(), pm.size());
          double hi[8] = {}, lo[8] = {};
          int tips_lo[8] = {}, tips_hi[8] = {};
          for (size_t k = 0; k < px.size(); ++k) {
            const int ph = int(std::floor(px[k].x)) & 7;
            (px[k].z >= 3.f ? hi : lo)[ph] += pm[k] / 8e-9;
          }
          const int per = sim.config().brush.samples_per_bristle;
          for (size_t b = 0; b * per < xs.size(); ++b) {
            Vec3 low = xs[b * per];
            for (int j = 0; j < per; ++j) if (xs[b * per + j].z < low.z) low = xs[b * per + j];
            const int ph = int(std::floor(low.x)) & 7;
            (low.z < 2.f ? tips_lo : tips_hi)[ph] += 1;
          }
          const BristleLoadHost lh = sim.load().to_host();
          double dep_hi[8] = {}, dep_lo[8] = {}, dep = 0;
          for (size_t j = 0; j < xs.size(); ++j) {
            const int ph = int(std::floor(xs[j].x)) & 7;
            (xs[j].z >= 2.f ? dep_hi : dep_lo)[ph] += lh.sweep[j] / 8e-9;
            dep += lh.sweep[j];
          }
          {
            float zr = 1e9f, gr = 1e9f, zv = 1e9f, gv = 1e9f;
            int near_r = 0, near_v = 0;
            for (size_t j = 0; j < xs.size(); ++j) {
              const bool on_ridge = (int(std::floor(xs[j].x)) & 7) < 4;
              const float m = lh.m[j];
              const float Rm = std::cbrt(3.f * m / (4.f * 3.14159f * 1000.f)) / 2e-4f;
              if (on_ridge) zr = std::min(zr, xs[j].z), gr = std::min(gr, lh.gap[j]), near_r += xs[j].z < 3.f + Rm;
              else zv = std::min(zv, xs[j].z), gv = std::min(gv, lh.gap[j]), near_v += xs[j].z < Rm;
            }
            int deciles[10] = {};
            for (size_t j = 0; j < xs.size(); ++j)
              if ((int(std::floor(xs[j].x)) & 7) >= 4 && xs[j].z < 2.5f) ++deciles[(j % per) * 10 / per];
            std::printf("  valley samples below z 2.5 by position along the bristle (root..tip):");
            for (int dd : deciles) std::printf(" %d", dd);
            std::printf("\n");
            std::printf("  over ridges: lowest sample z %.2f, least gap %.2f, %d within R_m of the top; over valleys: "
                        "lowest z %.2f, least gap %.2f, %d within R_m of the floor\n", zr, gr, near_r, zv, gv, near_v);
          }
          std::printf("  swept deposit %.3g kg of %.3g emitted; by sample x mod 8, z >= 2 / < 2 (cells):", dep,
                      sim.books().steps().back().transfer.emitted_from_bristles);
          for (int i = 0; i < 8; ++i) std::printf(" %.2f/%.2f", dep_hi[i], dep_lo[i]);
          std::printf("\n");
          std::printf("  particles (cells) high/low by x mod 8:");
          for (int i = 0; i < 8; ++i) std::printf(" %.2f/%.2f", hi[i], lo[i]);
          std::printf("; lowest sample of each bristle, z >= 2 / < 2 by x mod 8:");
          for (int i = 0; i < 8; ++i) std::printf(" %d/%d", tips_hi[i], tips_lo[i]);
          std::printf("\n");
        }
        std::printf("  x %5.1f: bristles %.3g kg, particles %.3g kg (%lld, mean z %.2f), absorbed %.3g emitted %.3g "
                    "to particles %.3g to grid %.3g; samples below z 4: %d of %zu, lowest %.2f\n",
                    x, st.census.bristles, st.census.particles, (long long)sim.particles().size(),
                    px.empty() ? 0.0 : pz / double(px.size()), st.transfer.absorbed_from_particles,
                    st.transfer.emitted_from_bristles, st.transfer.to_particles_from_grid,
                    st.transfer.to_grid_from_particles, low, xs.size(), zmin);
      }
    }
    for (int i = 0; i < 6; ++i) sim.step(pose_at(b, x1, kY, 0.f, false), kDt);
    sim.settle();
  }

  /// Host copy of the whole canvas (fields in WB_PAINT_FIELDS order).
  std::vector<std::vector<float>> canvas_fields(Simulator& sim) {
    const CanvasDims d = sim.canvas().dims();
    PaintWindow w(device_, Int3{d.width, d.height, d.depth});
    SimulatorTestAccess::canvas(sim).gather(w);
    return w.to_host();
  }

  /// New paint per column (row-major, cell volumes): the cells that are not dried, where a layer
  /// written dried, or a dried ground, lies under what a stroke laid.
  std::vector<double> fresh_columns(Simulator& sim) {
    const CanvasDims d = sim.canvas().dims();
    const auto f = canvas_fields(sim);
    const size_t dryness = 5;  // PaintWindow fields: density, r, y, b, oil, dryness
    std::vector<double> col(size_t(d.width) * d.height, 0.0);
    for (int z = 0; z < d.depth; ++z)
      for (size_t i = 0; i < col.size(); ++i) {
        const size_t id = size_t(z) * col.size() + i;
        if (f[dryness][id] < sim.config().params.grid.dry_threshold) col[i] += f[0][id];
      }
    return col;
  }

  /// The scumble's light brush: white (RYB 0), a third of its capacity.
  static void load_light_white(Simulator& sim, float load = 0.3f) {
    PaintLoad white;
    white.ryb[0] = white.ryb[1] = white.ryb[2] = 0.f;
    white.load = load;
    sim.load_paint(white);
  }
};

// --- pick-up -----------------------------------------------------------------------------------

TEST_F(LayerPropertiesTest, WhiteBrushCarriesRedPastAWetRedBand) {
  // A wet red band across the path (12 cells wide, 3 thick, oil 0.3); a brush loaded with
  // white (RYB 0, no pigment) dragged through it at 60 mm/s, pressure 0.6.
  constexpr int kW = 224, kH = 64, kBand0 = 64, kBand1 = 76;
  constexpr float kX0 = 24.f, kX1 = 184.f;
  SimConfig c = layer_config(CanvasDims{kW, kH, kDepth});
  Simulator sim(c, pose_at(c.brush, kX0, kY, 0.f, false));
  const PaintLoad r = red();
  write_layer(sim, [&](int x, int, int z) {
    PaintCell p;
    if (x >= kBand0 && x < kBand1 && z < 3)
      p.density = 1.f, p.pigment_r = r.ryb[0], p.pigment_y = r.ryb[1], p.pigment_b = r.ryb[2], p.oil = 0.3f;
    return p;
  });
  PaintLoad white;
  white.ryb[0] = white.ryb[1] = white.ryb[2] = 0.f;
  white.load = 1.f;
  Books books;
  books.open(sim);  // before the load: the books enter it with the first step's record
  sim.load_paint(white);
  drag(sim, kX0, kX1, 300.f, 0.6f);
  const double drift = books.max_drift(sim);
  std::printf("books from the layer: drift %.2e\n", drift);
  EXPECT_LT(drift, 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  const auto f = canvas_fields(sim);
  Renderer renderer(device_);
  const FloatImage albedo = renderer.render_albedo(SimulatorTestAccess::canvas(sim));
  // Over the track's central band, x in [x0, x1): the paint's red pigment share (red pigment
  // per unit paint, over cells holding paint) and the mean albedo of columns holding at least
  // 0.1 cell of paint.
  struct Look {
    double red = 0, paint = 0, rgb[3] = {0, 0, 0};
    int columns = 0;
  };
  const auto look = [&](int x0, int x1) {
    Look l;
    for (int y = int(kY) - 4; y <= int(kY) + 4; ++y)
      for (int x = x0; x < x1; ++x) {
        double col = 0;
        for (int z = 0; z < kDepth; ++z) {
          const size_t i = (size_t(z) * kH + y) * kW + x;
          col += f[0][i];
          l.red += f[0][i] * f[1][i];
        }
        l.paint += col;
        if (col < 0.1) continue;
        ++l.columns;
        for (int k = 0; k < 3; ++k) l.rgb[k] += albedo.at(x, y, k);
      }
    l.red /= std::max(l.paint, 1e-9);
    for (double& v : l.rgb) v /= std::max(l.columns, 1);
    return l;
  };
  const Look before = look(int(kX0) + 12, kBand0 - 8), after = look(kBand1 + 8, kBand1 + 48);
  const auto redness = [](const Look& l) { return l.rgb[0] - 0.5 * (l.rgb[1] + l.rgb[2]); };
  std::printf("before the band: %.1f cells of paint, red share %.3f, albedo %.3f %.3f %.3f (%d columns)\n",
              before.paint, before.red, before.rgb[0], before.rgb[1], before.rgb[2], before.columns);
  std::printf("after the band:  %.1f cells of paint, red share %.3f, albedo %.3f %.3f %.3f (%d columns)\n",
              after.paint, after.red, after.rgb[0], after.rgb[1], after.rgb[2], after.columns);
  // Tolerance: past the band the paint holds at least 0.05 red pigment per unit paint (white
  // with a twentieth of the band's red), and looks pink: red exceeds the mean of green and blue
  // by at least 0.04 of albedo (10 of 255) more than the white trail before the band does.
  EXPECT_GE(after.columns, 40) << "the brush left paint past the band";
  EXPECT_GE(after.red, 0.05) << "red carried past the band";
  EXPECT_GE(redness(after) - redness(before), 0.04) << "the paint past the band looks pink";
}


// --- ploughing ---------------------------------------------------------------------------------

TEST_F(LayerPropertiesTest, CleanBrushPloughsAWetLayer) {
  // A wet uniform layer 4 cells (0.8 mm) thick, oil 0.3; a clean brush dragged through it at
  // 60 mm/s, pressure 0.6. Paint per column across the track, averaged along its body. Most of
  // the layer near the bristles is particles (§5.2): they rest in the joint paint, not on the
  // canvas under it (docs/PARTICLES.md "Support in the joint paint").
  constexpr int kW = 192, kH = 64;
  constexpr float kLayer = 4.f, kX0 = 24.f, kX1 = 152.f;
  SimConfig c = layer_config(CanvasDims{kW, kH, kDepth});
  Simulator sim(c, pose_at(c.brush, kX0, kY, 0.f, false));
  write_layer(sim, [](int, int, int z) {
    PaintCell p;
    if (float(z) < kLayer) p.density = 1.f, p.pigment_r = 0.1f, p.pigment_y = 0.15f, p.pigment_b = 0.85f, p.oil = 0.3f;
    return p;
  });
  PaintLoad clean;
  clean.load = 0.f;
  sim.load_paint(clean);
  Books books;
  books.open(sim);
  drag(sim, kX0, kX1, 300.f, 0.6f);
  EXPECT_LT(books.max_drift(sim), 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  const auto f = canvas_fields(sim);
  std::vector<double> col(kH, 0.0);
  const int xa = int(kX0) + 32, xb = int(kX1) - 24;
  for (int y = 0; y < kH; ++y)
    for (int x = xa; x < xb; ++x)
      for (int z = 0; z < kDepth; ++z) col[size_t(y)] += f[0][(size_t(z) * kH + y) * kW + x] / double(xb - xa);
  if (verbose())
    for (int y = 0; y < kH; ++y) std::printf("%d:%.2f%c", y, col[size_t(y)], y + 1 < kH ? ' ' : '\n');
  const auto range = [&](int y0, int y1, bool want_max) {
    double v = want_max ? 0.0 : 1e9;
    for (int y = y0; y <= y1; ++y) v = want_max ? std::max(v, col[size_t(y)]) : std::min(v, col[size_t(y)]);
    return v;
  };
  const int yc = int(kY);
  const double track = range(yc - 2, yc + 1, false);
  const double left = range(yc - 12, yc - 3, true), right = range(yc + 2, yc + 12, true);
  double far = 0;
  for (int y = 0; y < 8; ++y) far += 0.5 * (col[size_t(y)] + col[size_t(kH - 1 - y)]) / 8.0;
  std::printf("column paint (cells): track %.2f, side ridges %.2f / %.2f, undisturbed %.2f; brush holds %.3g kg\n",
              track, left, right, far, sim.census().bristles);
  // Tolerances: the track loses at least 15 % of the layer (measured 70 % here; 26 % at 120 mm/s,
  // where the grid sees the bristles 10 cells apart, docs/PARTICLES.md); each side rises by at
  // least 3 % of it (0.12 cells, 30x the far field's deviation; measured 4.22-4.24 / 4.18-4.20);
  // the layer away from the brush is untouched.
  EXPECT_NEAR(far, kLayer, 0.01 * kLayer) << "the layer away from the brush";
  EXPECT_LT(track, 0.85 * kLayer) << "the brush lowers its track";
  EXPECT_GT(left, 1.03 * kLayer) << "paint pushed up beside the track";
  EXPECT_GT(right, 1.03 * kLayer) << "paint pushed up beside the track";
}

TEST_F(LayerPropertiesTest, LightBrushScumblesTheTopsOfADriedRidgedLayer) {
  // A dried blue layer with ridges across the stroke: 3 cells high and 4 wide, valleys of 1 cell
  // and 4 wide (period 8 along x). A lightly loaded white brush dragged lightly along x at 60 mm/s:
  // the brush rests on the ridges (the pen's pressure presses it into the surface it meets), so
  // the new paint per column is larger on the ridge tops than in the valleys.
  constexpr int kW = 192, kH = 64;
  constexpr float kX0 = 24.f, kX1 = 152.f;
  SimConfig c = layer_config(CanvasDims{kW, kH, kDepth});
  Simulator sim(c, pose_at(c.brush, kX0, kY, 0.f, false));
  auto ridge = [](int x) { return (x & 7) < 4; };
  write_layer(sim, [&](int x, int, int z) {
    PaintCell p;
    if (z < (ridge(x) ? 3 : 1)) {
      p.density = 1.f, p.pigment_r = 0.1f, p.pigment_y = 0.15f, p.pigment_b = 0.85f, p.oil = 0.3f;
      p.dryness = 1.f;
    }
    return p;
  });
  Books books;
  books.open(sim);  // before the load: the books enter it with the first step's record
  load_light_white(sim, env_or("WB_LAYER_LOAD", 0.3f));
  drag(sim, kX0, kX1, 300.f, env_or("WB_LAYER_PRESSURE", 0.1f));
  EXPECT_LT(books.max_drift(sim), 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  // New paint: the cells that are not dried (the layer's cells all are).
  const std::vector<double> col = fresh_columns(sim);
  double tops = 0, valleys = 0;
  int n_tops = 0, n_valleys = 0;
  for (int y = int(kY) - 4; y <= int(kY) + 4; ++y)
    for (int x = int(kX0) + 24; x < int(kX1) - 16; ++x) {
      const double fresh = col[size_t(y) * kW + x];
      (ridge(x) ? tops : valleys) += fresh;
      (ridge(x) ? n_tops : n_valleys) += 1;
    }
  tops /= n_tops, valleys /= n_valleys;
  std::printf("new paint per column: ridge tops %.4f, valleys %.4f cells (ratio %.2f)\n", tops, valleys,
              tops / std::max(valleys, 1e-12));
  EXPECT_GT(tops + valleys, 0.0) << "the brush left no paint";
  EXPECT_GT(tops, 1.2 * valleys) << "a scumble catches the paint on the tops of the dried layer";
}

TEST_F(LayerPropertiesTest, LightBrushPaintsOnADriedStrokeWhateverItsHeight) {
  // A dried stroke 20 cells wide across the drag, its top cell full or partly filled; the light
  // brush of the scumble test dragged over it. It lays as much on the stroke as on the canvas
  // before it, and does not push what it laid there off the stroke's far edge. (With a partly
  // filled top the bristles once rested on the whole cell, half a cell above the surface the
  // transfer measures from, and the particles sank into that cell, where the grid holds no wet
  // paint: the stroke took nothing and a pile formed past its edge. docs/TRANSFER.md.)
  constexpr int kW = 192, kH = 64, kOn0 = 80, kOn1 = 100;
  constexpr float kX0 = 24.f, kX1 = 152.f;
  // The last: a 2.5-cell stroke under the dried trace of its wet top (0.06 and 0.02 of a cell in
  // the two cells above), as a stroke that dried leaves it.
  for (const float H : {1.2f, 1.5f, 2.f, 2.5f, -2.5f}) {
    SimConfig c = layer_config(CanvasDims{kW, kH, kDepth});
    Simulator sim(c, pose_at(c.brush, kX0, kY, 0.f, false));
    write_layer(sim, [&](int x, int, int z) {
      PaintCell p;
      const float top = std::abs(H);
      float d = x >= kOn0 && x < kOn1 ? std::clamp(top - float(z), 0.f, 1.f) : 0.f;
      if (H < 0.f && x >= kOn0 && x < kOn1 && z == 3) d = 0.06f;
      if (H < 0.f && x >= kOn0 && x < kOn1 && z == 4) d = 0.02f;
      if (d > 0.f) p.density = d, p.pigment_r = 0.1f, p.pigment_y = 0.15f, p.pigment_b = 0.85f, p.oil = 0.3f, p.dryness = 1.f;
      return p;
    });
    load_light_white(sim);
    drag(sim, kX0, kX1, 300.f, 0.1f);
    EXPECT_EQ(sim.counters().nonfinite_events, 0);
    // New paint per column, over the track's middle rows.
    const std::vector<double> col = fresh_columns(sim);
    auto fresh = [&](int x) {
      double v = 0;
      for (int y = int(kY) - 4; y <= int(kY) + 4; ++y) v += col[size_t(y) * kW + x];
      return v / 9.0;
    };
    double before = 0, on = 0, past = 0;
    for (int x = 50; x < kOn0; ++x) before += fresh(x) / (kOn0 - 50);
    for (int x = kOn0; x < kOn1; ++x) on += fresh(x) / (kOn1 - kOn0);
    for (int x = kOn1; x < kOn1 + 10; ++x) past = std::max(past, fresh(x));
    std::printf("dried stroke %.1f cells high%s: new paint per column %.3f before it, %.3f on it, at most %.3f just past it\n",
                std::abs(H), H < 0.f ? " under a dried trace" : "", before, on, past);
    EXPECT_GT(before, 0.05) << "the brush paints the canvas";
    EXPECT_GT(on, 0.6 * before) << "the brush paints the dried stroke " << H << " cells high";
    EXPECT_LT(past, 4.0 * before) << "no paint pushed off the stroke's far edge";
  }
}

TEST_F(LayerPropertiesTest, DryBrushCatchesTheWeaveOfALinenCanvas) {
  // The scumble test's light brush (white, load 0.3, pressure 0.1) dragged over a smooth board and
  // over linen (threads 1 mm apart, 0.3 mm relief, on 0.2 mm of primer) primed in a dark colour:
  // on linen the bristles rest on the threads' crowns and bridge the hollows, so the paint covers
  // less of the track than on the board, and lies on the crowns (docs/STUDIO.md "Canvas texture").
  constexpr int kW = 160, kH = 64;
  constexpr float kX0 = 24.f, kX1 = 136.f;
  double cover[2] = {}, crowns = 0, hollows = 0;
  for (const Weave weave : {Weave::Smooth, Weave::Linen}) {
    SimConfig c = layer_config(CanvasDims{kW, kH, kDepth});
    Simulator sim(c, pose_at(c.brush, kX0, kY, 0.f, false));
    const CanvasGround g = CanvasGround::of(weave);
    const Vec3 primer(0.2f, 0.2f, 0.6f);
    sim.lay_ground(g, primer);
    const WeaveField w = weave_field(g, c.params.grid.cell_size, primer);
    Books books;
    books.open(sim);
    if (weave == Weave::Linen) {
      EXPECT_NEAR(sim.books().external_total(), sim.census().total(), 1e-6 * sim.census().total())
          << "the books record the primer as paint from outside";
      EXPECT_GT(sim.canvas().total_density(), double(kW) * kH * w.base) << "the primer is laid under the hollows";
      EXPECT_EQ(sim.books().steps().size(), 0u);
    }
    load_light_white(sim);
    drag(sim, kX0, kX1, 300.f, 0.1f);
    EXPECT_EQ(sim.counters().nonfinite_events, 0);
    EXPECT_LT(books.max_drift(sim), 1e-4);
    const std::vector<double> col = fresh_columns(sim);
    int covered = 0, columns = 0, n_crowns = 0, n_hollows = 0;
    for (int y = int(kY) - 4; y <= int(kY) + 4; ++y)
      for (int x = int(kX0) + 24; x < int(kX1) - 16; ++x) {
        const double fresh = col[size_t(y) * kW + x];
        covered += fresh > 0.05, ++columns;
        if (weave != Weave::Linen) continue;
        // Crowns: the top third of the relief; hollows: the bottom third.
        const float h = (weave_height(w, float(x) + 0.5f, float(y) + 0.5f) - w.base) / w.relief;
        if (h > 0.67f) crowns += fresh, ++n_crowns;
        if (h < 0.33f) hollows += fresh, ++n_hollows;
      }
    cover[weave == Weave::Linen] = double(covered) / columns;
    if (weave == Weave::Linen) crowns /= std::max(n_crowns, 1), hollows /= std::max(n_hollows, 1);
  }
  std::printf("dry brush: covers %.2f of the track on a smooth board, %.2f on linen; on linen %.3f cells of paint "
              "per column on the crowns, %.3f in the hollows\n",
              cover[0], cover[1], crowns, hollows);
  EXPECT_GT(cover[0], 0.5) << "the light brush paints the smooth board";
  EXPECT_LT(cover[1], 0.9 * cover[0]) << "linen's hollows stay bare under a dry brush";
  EXPECT_GT(crowns, 1.5 * hollows) << "the paint lies on the threads' crowns";
}

}  // namespace
// --- support ------------------------------------------------------------------------------------

TEST_F(LayerPropertiesTest, ParticlesComeToRestOnAWetLayer) {
  // A wet blue layer 4 cells (0.8 mm) thick; a patch of red paint particles released 8 cells above
  // it, 12 cells beside a lifted brush (inside D0, so they stay particles; outside D1).
  constexpr int kW = 96, kH = 64;
  constexpr float kLayer = 4.f;
  SimConfig c = layer_config(CanvasDims{kW, kH, kDepth});
  const BrushPose lifted = pose_at(c.brush, 48.f, kY, 0.f, false);
  Simulator sim(c, lifted);
  write_layer(sim, [](int, int, int z) {
    PaintCell p;
    if (float(z) < kLayer) p.density = 1.f, p.pigment_r = 0.1f, p.pigment_y = 0.15f, p.pigment_b = 0.85f, p.oil = 0.3f;
    return p;
  });
  ParticleHost drop;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) {
      drop.x.push_back(Vec3(60.5f + float(i), kY - 3.f + float(j), kLayer + 8.f));
      drop.v.push_back(Vec3(0.f, 0.f, 0.f));
      drop.m.push_back(0.5f * c.params.transfer.cell_mass());
      drop.pigment_r.push_back(0.9f), drop.pigment_y.push_back(0.05f), drop.pigment_b.push_back(0.05f);
      drop.oil.push_back(0.3f), drop.dryness.push_back(0.f);
    }
  SimulatorTestAccess::particles(sim).append(drop);
  Books books;
  books.open(sim);
  for (int s = 0; s < 30; ++s) sim.step(lifted, kDt);  // half a second
  EXPECT_LT(books.max_drift(sim), 1e-4);
  EXPECT_EQ(sim.counters().nonfinite_events, 0);
  // Where the red paint is: the particles left, and the red in the canvas and window.
  const ParticleHost left = sim.particles().to_host();
  double zsum = 0, msum = 0;
  for (size_t k = 0; k < left.size(); ++k)
    if (left.pigment_r[k] > 0.5f) zsum += double(left.m[k]) * left.x[k].z, msum += left.m[k];
  SimulatorTestAccess::grid(sim).window().flush();
  const auto f = canvas_fields(sim);
  const double cell_mass = c.params.transfer.cell_mass();
  for (int z = 0; z < kDepth; ++z)
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const size_t id = (size_t(z) * kH + y) * kW + x;
        const double red = f[0][id] * std::max(0.0, double(f[1][id]) - 0.1) / 0.8;  // share of the red paint
        zsum += red * cell_mass * (z + 0.5), msum += red * cell_mass;
      }
  const double mean_z = zsum / msum;
  std::printf("red paint: %zu particles left, mean height %.2f cells (layer top %.0f)\n", left.size(), mean_z,
              kLayer);
  // On the wet surface, within a cell and a half; paint that fell through lies at z < 2.
  EXPECT_GT(mean_z, kLayer - 1.5);
  EXPECT_LT(mean_z, kLayer + 1.5);
}

}  // namespace wb::test
