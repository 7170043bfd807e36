// Rheology of the grid paint (docs/GRID.md "Rheology"): the regularised Herschel–Bulkley law,
// shear thinning measured by the grid's own strain rate, and paint at rest — a stiff ridge and
// stiff grooves hold their shape for 2 s, an oily ridge levels, a drop on a slope of wet paint
// slumps where the slope is steeper than its yield stress holds and stays on a gentle one.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "backend_fixture.h"
#include "core/grid/grid_fields.h"
#include "core/grid/rheology.h"
#include "core/io/document.h"
#include "core/render/renderer.h"
#include "grid/grid_test_util.h"

namespace wb::test {

class RheologyTest : public BackendTest {};

TEST(Rheology, ApparentViscosityIsHerschelBulkleyAboveTheCriticalRate) {
  const HerschelBulkley hb{40.f, 5.f, 0.6f};
  const float m = 1e4f;
  for (float rate : {0.1f, 1.f, 10.f, 100.f, 1000.f, 1e4f}) {
    const float tau = apparent_viscosity(hb, rate, m) * rate;
    const float expect = hb.tau_y + hb.K * std::pow(rate, hb.n);
    EXPECT_NEAR(tau, expect, 0.01f * expect) << "gamma_dot " << rate;
  }
  // At rest the regularised paint is a finite, very viscous liquid: tau_y m + K m^(1-n).
  const float mu0 = apparent_viscosity(hb, 0.f, m);
  EXPECT_NEAR(mu0, hb.tau_y * m + hb.K * std::pow(m, 1.f - hb.n), 1e-3f * mu0);
  // Shear thinning: the apparent viscosity falls monotonically with the strain rate.
  float last = mu0;
  for (float rate = 1e-5f; rate < 1e5f; rate *= 3.f) {
    const float mu = apparent_viscosity(hb, rate, m);
    EXPECT_LE(mu, last * (1.f + 1e-5f)) << rate;
    last = mu;
  }
  // The oil fraction moves between the end members: geometric in tau_y and K, linear in n.
  const HerschelBulkley stiff{300.f, 30.f, 0.5f}, oily{0.1f, 0.05f, 1.f};
  const HerschelBulkley mid = rheology_at_oil(0.5f, stiff, oily);
  EXPECT_NEAR(mid.tau_y, std::sqrt(300.f * 0.1f), 1e-3f);
  EXPECT_NEAR(mid.K, std::sqrt(30.f * 0.05f), 1e-4f);
  EXPECT_NEAR(mid.n, 0.75f, 1e-6f);
}

namespace {
/// Apparent viscosity the grid computes in the middle of a layer sheared at `rate` (u = rate z).
float sheared_layer_viscosity(const Device& device, float rate, float oil) {
  TileStore canvas(device, CanvasDims{64, 64, 32});
  Grid g(canvas, GridParams{}, Int3{16, 16, 12}, Int3{0, 0, 0});
  const int layer = 8;
  paint_cells(g, [&](int, int, int k) { return k < layer ? 1.f : 0.f; }, oil);
  g.classify();
  const GridDims d = g.dims();
  std::vector<float> u(size_t(d.nu()));
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i <= d.nx; ++i) u[size_t(d.uidx(i, j, k))] = rate * (float(k) + 0.5f);
  g.window().velocity(0).copy_from_host(u);
  g.rheology();
  const auto mu = g.apparent_viscosity().to_host();
  double acc = 0;
  int n = 0;
  for (int k = 2; k < layer - 2; ++k)
    for (int j = 4; j < d.ny - 4; ++j)
      for (int i = 4; i < d.nx - 4; ++i) {
        acc += mu[size_t(d.cell(i, j, k))];
        ++n;
      }
  return float(acc / n);
}

/// Column volume (integral of density, cells) at window column (i, j).
float column(const GridDims& d, const std::vector<float>& rho, int i, int j) {
  float h = 0.f;
  for (int k = 0; k < d.nz; ++k) h += rho[size_t(d.cell(i, j, k))];
  return h;
}
}  // namespace

TEST(Rheology, AFilmFaceCarriesNothingFromAnEmptyColumnWhateverItsFields) {
  // Two film columns: a bare one (h = 0) on a dried ridge 2 cells high beside a film 0.5 cells
  // thick in the valley. Gravity drives from the ridge to the valley, so the bare column is
  // upwind. Its paint's fields are never written in a sub-step that nothing reaches it, so they
  // hold whatever the buffer held: no value of them may make it carry paint (a negative yield
  // stress let an empty column pass the yield test and carry an infinite flux).
  const int64_t n = 2;
  std::vector<float> col(size_t(kFilmFields) * n, 0.f);
  col[kFilmH * n + 0] = 0.f, col[kFilmBase * n + 0] = 2.f;
  col[kFilmH * n + 1] = 0.5f, col[kFilmBase * n + 1] = 0.f;
  col[kFilmTau * n + 1] = 0.5f, col[kFilmK * n + 1] = 1.f;
  const FilmFlow f{HerschelBulkley{100.f, 10.f, 1.f}, HerschelBulkley{0.1f, 0.05f, 1.f}, 8000.f, 0.f, 2e-4f, 1e-3f,
                   0.033f};
  for (const float tau : {-1e30f, -1.f, 0.f, NAN, 1e30f})
    for (const float K : {-1e-30f, 0.f, 1e-30f, NAN, 1.f}) {
      col[kFilmTau * n + 0] = tau, col[kFilmK * n + 0] = K;
      EXPECT_EQ(film_face(col.data(), n, 0, 1, 0.f, f), 0.f) << "tau_y " << tau << ", K " << K;
      EXPECT_EQ(film_face(col.data(), n, 1, 0, 0.f, f), 0.f) << "tau_y " << tau << ", K " << K;
    }
  // The valley's film, upwind of an empty column lower still, does flow into it.
  col[kFilmBase * n + 0] = 0.f, col[kFilmBase * n + 1] = 2.f;
  EXPECT_LT(film_face(col.data(), n, 0, 1, 0.f, f), 0.f) << "from column 1 into column 0";
}

TEST_F(RheologyTest, ShearedPaintThinsByTheModelsRatio) {
  const GridParams p;
  const float oil = 0.3f;
  const HerschelBulkley hb = rheology_at_oil(oil, {p.yield_stress_stiff, p.consistency_stiff, p.flow_index_stiff},
                                             {p.yield_stress_oily, p.consistency_oily, p.flow_index_oily});
  const float slow = 10.f, fast = 1000.f;  // 1/s: a brush drags paint at 10^3 - 10^4 1/s
  const float mu_slow = sheared_layer_viscosity(device_, slow, oil);
  const float mu_fast = sheared_layer_viscosity(device_, fast, oil);
  const float model = apparent_viscosity(hb, fast, p.regularisation) / apparent_viscosity(hb, slow, p.regularisation);
  std::printf("[ shear ] oil %.1f: mu(%g/s) = %.3g Pa s, mu(%g/s) = %.3g Pa s, ratio %.4f (model %.4f)\n", oil, slow,
              mu_slow, fast, mu_fast, mu_fast / mu_slow, model);
  EXPECT_NEAR(mu_slow, apparent_viscosity(hb, slow, p.regularisation), 0.1f * mu_slow);
  EXPECT_NEAR(mu_fast / mu_slow, model, 0.1f * model);
  EXPECT_LT(mu_fast, 0.1f * mu_slow);  // strongly shear-thinning at oil 0.3
}

namespace {
struct RestResult {
  float ridge_before, ridge_after, groove_before, groove_after;
  float densest_first, densest_last;  ///< highest density any cell reached in each half of the time
};

/// A ridge 15 cells (3 mm) high on a 4-cell layer and, beside it, grooves 2 cells (0.4 mm) apart,
/// left alone for `seconds`. Uniform along y, `width` cells wide. With WB_GALLERY_DIR set, the
/// painting before and after is saved there (rest-oil-<oil>-<s>s.ora) for docs/EXAMPLES.md.
RestResult paint_at_rest(const Device& device, float oil, float seconds, int width = 6) {
  TileStore canvas(device, CanvasDims{128, 64, 64});
  GridParams p;
  Grid g(canvas, p, Int3{96, width, 24}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  auto height = [](int i) {
    if (i >= 8 && i < 40) return 4.f + 15.f * std::max(0.f, 1.f - std::fabs(float(i) + 0.5f - 24.f) / 16.f);
    if (i >= 56 && i < 88) return (i % 2) ? 6.f : 4.f;  // grooves: 2 cells deep, 0.4 mm apart
    return 4.f;
  };
  paint_cells(g, [&](int i, int, int k) { return std::clamp(height(i) - float(k), 0.f, 1.f); }, oil);
  auto measure = [&](float& ridge, float& groove) {
    const auto rho = host_density(g);
    ridge = 0.f;
    for (int i = 8; i < 40; ++i) ridge = std::max(ridge, column(d, rho, i, 3) - 4.f);
    double a = 0;
    for (int i = 60; i < 84; i += 2) a += column(d, rho, i + 1, 3) - column(d, rho, i, 3);
    groove = float(a / 12.0);
  };
  const char* gallery = std::getenv("WB_GALLERY_DIR");
  auto save = [&](float at) {
    if (gallery == nullptr) return;
    g.window().flush();
    char name[64];
    std::snprintf(name, sizeof name, "/rest-oil-%.1f-%.0fs.ora", oil, at);
    Renderer renderer(device);
    save_painting(std::string(gallery) + name, canvas, renderer.render(canvas, Camera::top(canvas.dims())),
                  nlohmann::json{{"generator", "RheologyTest paint_at_rest"}, {"oil", oil}, {"seconds", at}});
  };
  RestResult r{};
  measure(r.ridge_before, r.groove_before);
  save(0.f);
  const int steps = int(std::lround(seconds / p.dt));
  for (int s = 0; s < steps; ++s) {
    g.step(p.dt);
    const auto rho = host_density(g);
    float& densest = s < steps / 2 ? r.densest_first : r.densest_last;
    for (float x : rho) densest = std::max(densest, x);
  }
  save(seconds);
  measure(r.ridge_after, r.groove_after);
  std::printf("[ rest ] oil %.1f, %.0f s: ridge %.2f -> %.2f cells, grooves %.2f -> %.2f cells, densest cell %.2f then %.2f\n",
              oil, seconds, r.ridge_before, r.ridge_after, r.groove_before, r.groove_after, r.densest_first,
              r.densest_last);
  return r;
}
}  // namespace

TEST_F(RheologyTest, StiffPaintHoldsRidgesAndGroovesOilyPaintLevels) {
  if (std::getenv("WB_GALLERY_DIR")) {  // the gallery's wider strip: docs/EXAMPLES.md "Paint at rest"
    for (float oil : {0.1f, 0.8f}) paint_at_rest(device_, oil, 2.f, 40);
    return;
  }
  const RestResult stiff = paint_at_rest(device_, 0.1f, 2.f);
  EXPECT_GE(stiff.ridge_after, 0.95f * stiff.ridge_before);
  EXPECT_GE(stiff.groove_after, 0.9f * stiff.groove_before);
  const RestResult oily = paint_at_rest(device_, 0.8f, 2.f);
  EXPECT_LE(oily.ridge_after, 0.8f * oily.ridge_before);
  // The collapse packs paint into the cells it lands in (a flow field the projection has not
  // made divergence-free); the compression source spreads it again: in the second second no
  // cell holds more than a quarter above full. Without the source it stayed above 6.
  EXPECT_LE(oily.densest_last, 1.25f);
}

namespace {
/// A drop of red paint 4 cells (0.8 mm) thick on a slope of wet blue paint of the same oil
/// (0.55: yield stress 3.7 Pa), left alone 2 s. Returns how far the drop's centre (the red pigment)
/// moved downhill, cells. Uniform along y.
float drop_on_slope(const Device& device, float slope) {
  TileStore canvas(device, CanvasDims{128, 64, 64});
  GridParams p;
  Grid g(canvas, p, Int3{64, 6, 32}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  auto surface = [&](int i) { return 2.f + slope * std::clamp(float(i) + 0.5f - 8.f, 0.f, 20.f); };
  Fields f = empty_fields(g);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const size_t c = size_t(d.cell(i, j, k));
        const float z = float(k), s = surface(i);
        const bool drop = i >= 15 && i < 21 && z >= s && z < s + 4.f;
        if (z < s || drop) {
          f[0][c] = 1.f, f[1][c] = drop ? 0.9f : 0.05f, f[2][c] = 0.05f, f[3][c] = drop ? 0.05f : 0.9f;
          f[4][c] = 0.55f;
        }
      }
  g.window().paint().from_host(f);
  auto centre = [&] {
    const auto rho = host_density(g);
    const auto red = g.window().paint().pigment_r.to_host();
    double m = 0, x = 0;
    for (size_t c = 0; c < rho.size(); ++c) {
      int i, j, k;
      d.decompose_cell(int64_t(c), i, j, k);
      const double w = rho[c] * std::max(0.f, red[c] - 0.05f);
      m += w, x += w * (i + 0.5);
    }
    return float(x / m);
  };
  const float x0 = centre();
  for (int s = 0; s < int(std::lround(2.f / p.dt)); ++s) g.step(p.dt);
  const float moved = x0 - centre();
  std::printf("[ slope ] %.2f (%.0f deg): the drop moved %.2f cells downhill in 2 s\n", slope,
              std::atan(slope) * 180.f / 3.14159265f, moved);
  return moved;
}
}  // namespace

TEST_F(RheologyTest, DropSlumpsOnASteepSlopeAndHoldsOnAGentleOne) {
  // A slope of a material with yield stress c stands up to the critical height
  // H_c = 4 (c / rho0 g) sin(b) / (1 - cos(b)) (Culmann's wedge, no friction): with c = 3.7 Pa,
  // 3.6 mm at 45 degrees, below the 5.2 mm of this slope, and 30 mm at 6 degrees; the drop itself,
  // 0.8 mm high, is below the 1.5 mm of a vertical cut (b = 90 degrees).
  EXPECT_GT(drop_on_slope(device_, 1.f), 2.f);
  EXPECT_LT(std::fabs(drop_on_slope(device_, 0.1f)), 0.3f);
}

namespace {
/// A bead of paint 2 mm (10 cells) on a side on a bare canvas tilted `tilt` degrees from the
/// table, left alone 2 s. Returns how far its centre of mass moved down the canvas (+y) and
/// across it (x), cells.
std::pair<float, float> bead_on_easel(const Device& device, float oil, float tilt) {
  TileStore canvas(device, CanvasDims{64, 160, 32});
  GridParams p;
  p.tilt = tilt;
  // Room to run down the canvas; flat, the bead in the middle of the window, whose walls are
  // as far on every side.
  Grid g(canvas, p, Int3{32, tilt > 0.f ? 120 : 32, 16}, Int3{0, 0, 0});
  paint_cells(g, [](int i, int j, int k) { return i >= 11 && i < 21 && j >= 11 && j < 21 && k < 10 ? 1.f : 0.f; }, oil);
  const GridDims d = g.dims();
  auto centre = [&] {
    const auto rho = host_density(g);
    double m = 0, x = 0, y = 0;
    for (size_t c = 0; c < rho.size(); ++c) {
      int i, j, k;
      d.decompose_cell(int64_t(c), i, j, k);
      m += rho[c], x += rho[c] * (i + 0.5), y += rho[c] * (j + 0.5);
    }
    return std::pair<double, double>(x / m, y / m);
  };
  const auto [x0, y0] = centre();
  for (int s = 0; s < int(std::lround(2.f / p.dt)); ++s) g.step(p.dt);
  const auto [x1, y1] = centre();
  std::printf("[ easel ] oil %.1f, canvas tilted %2.0f deg: the bead's centre moved %.2f cells down the canvas, "
              "%.2f across, in 2 s\n", oil, tilt, y1 - y0, x1 - x0);
  return {float(y1 - y0), float(x1 - x0)};
}
}  // namespace

TEST_F(RheologyTest, OilyPaintRunsDownAnUprightCanvasStiffPaintStays) {
  // Upright, a 2 mm bead pulls its base with rho0 g h = 20 Pa: far above oily paint's yield stress
  // (oil 0.9: 0.2 Pa), below stiff paint's (oil 0.1: 135 Pa). Flat, neither moves sideways.
  EXPECT_GE(bead_on_easel(device_, 0.9f, 90.f).first, 25.f) << "oily paint runs 5 mm down in 2 s";
  EXPECT_LE(std::fabs(bead_on_easel(device_, 0.1f, 90.f).first), 1.f) << "stiff paint stays within 0.2 mm";
  for (float oil : {0.9f, 0.1f}) {
    const auto [down, across] = bead_on_easel(device_, oil, 0.f);
    EXPECT_LE(std::fabs(down), 0.25f) << oil;
    EXPECT_LE(std::fabs(across), 0.25f) << oil;
  }
}

namespace {
/// A layer about a cell thick (0.2 mm) with grooves across x two cells apart (columns of 1 - a and
/// 1 + a cells), left alone `seconds`. Returns the grooves' depth after over before (the mean
/// difference between neighbouring columns) and the relative change of the paint's mass.
std::pair<double, double> grooves_at_rest(const Device& device, float oil, float seconds, float a = 0.3f) {
  TileStore canvas(device, CanvasDims{64, 32, 16});
  GridParams p;
  Grid g(canvas, p, Int3{48, 16, 8}, Int3{0, 0, 0});
  const auto column = [a](int i) { return i % 2 ? 1.f + a : 1.f - a; };
  paint_cells(g, [&](int i, int, int k) { return k == 0 ? std::min(1.f, column(i)) : (k == 1 ? std::max(0.f, column(i) - 1.f) : 0.f); },
              oil);
  const GridDims d = g.dims();
  auto depth = [&] {
    const auto rho = host_density(g);
    double sum = 0, mass = 0;
    int n = 0;
    for (int j = 4; j < 12; ++j)
      for (int i = 8; i < 40; ++i, ++n) {
        double a = 0, b = 0;
        for (int k = 0; k < d.nz; ++k) a += rho[size_t(d.cell(i, j, k))], b += rho[size_t(d.cell(i + 1, j, k))];
        sum += std::fabs(a - b);
      }
    for (float r : rho) mass += r;
    return std::pair<double, double>(sum / n, mass);
  };
  const auto [before, m0] = depth();
  for (int s = 0; s < int(std::lround(seconds / p.dt)); ++s) g.step(p.dt);
  const auto [after, m1] = depth();
  std::printf("[ film ] oil %.2f: grooves 2 cells apart and %.2f cells deep in a layer a cell thick keep %.1f %% of "
              "their depth after %.0f s; mass %+.2g\n", oil, 2 * a, 100 * after / before, seconds, (m1 - m0) / m0);
  return {after / before, (m1 - m0) / m0};
}
}  // namespace

TEST_F(RheologyTest, ThinOilyPaintLevelsStiffPaintKeepsItsGrooves) {
  // Paint thinner than a cell has no pressure across a groove in the grid; as a film it levels
  // where the stress at its base, from gravity and surface tension, passes the yield stress
  // (oil 0.95: 0.15 Pa; oil 0.1: 135 Pa).
  const auto [oily, oily_mass] = grooves_at_rest(device_, 0.95f, 2.f);
  EXPECT_LE(oily, 0.5) << "oil-rich paint levels";
  EXPECT_LE(std::fabs(oily_mass), 1e-5);
  // Grooves 0.4 cells deep (columns 0.8 and 1.2): the capillary stress at the film's depth the
  // grid's shortest groove sees (kFilmCapillaryDepth), sigma 8 a / dx^2 x 0.45 dx = 119 Pa at
  // 0.033 N/m, is below stiff paint's yield stress.
  const auto [stiff, stiff_mass] = grooves_at_rest(device_, 0.1f, 10.f, 0.2f);
  EXPECT_GE(stiff, 0.99) << "stiff paint keeps its grooves";
  EXPECT_LE(std::fabs(stiff_mass), 1e-5);
}

TEST_F(RheologyTest, SurfaceTensionLevelsStiffPaintOnlyToItsYieldStress) {
  // Grooves 0.6 cells deep (columns 0.7 and 1.3) pull the base with 178 Pa, more than stiff
  // paint's 135 Pa: a Bingham film levels them until the capillary stress, in proportion to the
  // depth, falls to the yield stress (Liu & Mei's plug), to 135 / 178 = 76 % of their depth, and
  // holds them there.
  const auto [stiff, stiff_mass] = grooves_at_rest(device_, 0.1f, 10.f);
  const GridParams p;
  const HerschelBulkley hb =
      rheology_at_oil(0.1f, HerschelBulkley{p.yield_stress_stiff, p.consistency_stiff, p.flow_index_stiff},
                      HerschelBulkley{p.yield_stress_oily, p.consistency_oily, p.flow_index_oily});
  const double a = 0.3, stress = double(p.surface_tension) * 8.0 * a / double(p.cell_size) * kFilmCapillaryDepth;
  EXPECT_NEAR(stiff, hb.tau_y / stress, 0.03) << "levelled to the yield stress";
  EXPECT_LE(std::fabs(stiff_mass), 1e-5);
}

TEST_F(RheologyTest, PaintFlowsOnlyInTheFlowColumns) {
  // Grid::set_flow_columns (docs/GRID.md "The window's walls"): the oily grooved layer of the
  // test above, its window's columns x >= 24 outside the flow: there the paint is kept cell for
  // cell (walls, as off the canvas), while the grooves inside level as they do in a whole window.
  TileStore canvas(device_, CanvasDims{64, 32, 16});
  GridParams p;
  Grid g(canvas, p, Int3{48, 16, 8}, Int3{0, 0, 0});
  g.set_flow_columns(FlowColumns{-100, 24, -100, 100});
  const auto column = [](int i) { return i % 2 ? 1.3f : 0.7f; };
  paint_cells(
      g,
      [&](int i, int, int k) {
        return k == 0 ? std::min(1.f, column(i)) : (k == 1 ? std::max(0.f, column(i) - 1.f) : 0.f);
      },
      0.95f);
  const GridDims d = g.dims();
  const std::vector<float> before = host_density(g);
  for (int s = 0; s < int(std::lround(2.f / p.dt)); ++s) g.step(p.dt);
  const std::vector<float> after = host_density(g);
  const auto grooves = [&](const std::vector<float>& rho, int i0, int i1) {
    double sum = 0;
    int n = 0;
    for (int j = 4; j < 12; ++j)
      for (int i = i0; i < i1; ++i, ++n) {
        double a = 0, b = 0;
        for (int k = 0; k < d.nz; ++k) a += rho[size_t(d.cell(i, j, k))], b += rho[size_t(d.cell(i + 1, j, k))];
        sum += std::fabs(a - b);
      }
    return sum / n;
  };
  int changed = 0;
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 24; i < d.nx; ++i) changed += after[size_t(d.cell(i, j, k))] != before[size_t(d.cell(i, j, k))];
  double m0 = 0, m1 = 0;
  for (size_t c = 0; c < before.size(); ++c) m0 += before[c], m1 += after[c];
  const double inside = grooves(after, 4, 20) / grooves(before, 4, 20);
  std::printf("inside the flow columns the grooves keep %.1f %%; outside %d cells changed; mass %+.2g\n", 100 * inside,
              changed, (m1 - m0) / m0);
  EXPECT_LE(inside, 0.5) << "the grooves inside level";
  EXPECT_EQ(changed, 0) << "the paint outside is kept as it is";
  EXPECT_LE(std::fabs((m1 - m0) / m0), 1e-5);
}

}  // namespace wb::test
