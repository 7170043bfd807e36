// Grid step (paper §4.2): resting paint stays still, a moving plate pushes paint and piles
// it up, dried cells never move, drying makes cells solid, the viscous solve converges for the
// stiffest paint, and advection's mass drift is corrected.
#include <cmath>
#include <random>

#include "backend_fixture.h"
#include "grid/grid_test_util.h"

namespace wb::test {

class GridStepTest : public BackendTest {};

TEST_F(GridStepTest, StillPaintLayerStaysStill) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  Grid g(canvas, GridParams{}, Int3{48, 48, 16}, Int3{64, 64, 0});
  // A 6-cell layer with a thinner 3-cell region and a partly filled top: gravity acts.
  paint_cells(g, [](int i, int j, int k) {
    const int h = (i > 20 && i < 30) ? 3 : 6;
    return k < h ? 1.f : (k == h ? 0.3f : 0.f);
  });
  const auto rho0 = host_density(g);
  const float dt = g.params().dt;
  int iterations = 0;
  for (int s = 0; s < 100; ++s) {
    g.step(dt);
    iterations = std::max(iterations, g.stats().viscosity_iterations);
  }
  std::printf("[ still ] most CG iterations in a step: %d\n", iterations);
  const float speed = g.max_fluid_speed();
  EXPECT_LT(speed * dt, 1e-4f) << "spurious current " << speed << " cells/s";
  const auto rho1 = host_density(g);
  double change = 0;
  for (size_t i = 0; i < rho0.size(); ++i) change = std::max(change, double(std::fabs(rho1[i] - rho0[i])));
  // The 3-cell step (5.9 Pa at its foot) is below the yield stress of oil-0.2 paint (60 Pa): it
  // creeps only at the regularised viscosity tau_y m = 6e5 Pa s, about 1e-4 cells in 1.7 s.
  EXPECT_LT(change, 1e-3);
}

TEST_F(GridStepTest, PlatePushesPaintAndPilesItUp) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  Grid g(canvas, p, Int3{64, 32, 24}, Int3{32, 32, 0});
  const GridDims d = g.dims();
  // Block of paint x in [20, 44), y in [8, 24), 5 cells tall.
  paint_cells(g, [](int i, int j, int k) { return (i >= 20 && i < 44 && j >= 8 && j < 24 && k < 5) ? 1.f : 0.f; });
  const auto rho0 = host_density(g);
  const Vec3 c0 = centroid(d, rho0);
  HostBristles br(device_, d.cells());
  const float speed = 30.f, dt = p.dt;  // half a cell per step
  float x0 = 14.f;
  auto height_in_front = [&](const std::vector<float>& rho, float plate_front) {
    int best = 0;
    for (int j = 10; j < 22; ++j)
      for (int i = int(plate_front); i < std::min(int(plate_front) + 6, d.nx); ++i) {
        int h = 0;
        for (int k = 0; k < d.nz; ++k)
          if (rho[size_t(d.cell(i, j, k))] >= 0.5f) h = k + 1;
        best = std::max(best, h);
      }
    return best;
  };
  const int h0 = height_in_front(rho0, 20.f);
  const double m0 = sum(rho0);
  for (int s = 0; s < 40; ++s) {
    br.plate(d, x0, x0 + 2.f, 4, 28, 14, speed);
    g.set_bristles(br.field());
    g.step(dt);
    x0 += speed * dt;
  }
  const auto rho1 = host_density(g);
  const Vec3 c1 = centroid(d, rho1);
  EXPECT_GT(c1.x, c0.x + 2.f) << "paint should move with the plate";
  const int h1 = height_in_front(rho1, x0 + 2.f);
  EXPECT_GT(h1, h0) << "paint should pile up in front of the plate";
  EXPECT_NEAR(sum(rho1), m0, 1e-4 * m0);
}

TEST_F(GridStepTest, DriedCellsNeverMove) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  Grid g(canvas, p, Int3{64, 32, 24}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  // Wet block in front of a dried wall (x in [40, 44)) and a dried floor crust under it.
  Fields f = empty_fields(g);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const size_t c = size_t(d.cell(i, j, k));
        const bool wall = i >= 40 && i < 44 && j >= 4 && j < 28 && k < 8;
        const bool crust = k == 0 && i >= 16 && i < 40 && j >= 4 && j < 28;
        const bool wet = i >= 20 && i < 40 && j >= 8 && j < 24 && k >= 1 && k < 6;
        if (wall || crust) {
          f[0][c] = 0.9f;
          f[3][c] = 1.f;
          f[5][c] = 1.f;
        } else if (wet) {
          f[0][c] = 1.f;
          f[1][c] = 1.f;
          f[4][c] = 0.8f;
        }
      }
  g.window().paint().from_host(f);
  HostBristles br(device_, d.cells());
  float x0 = 14.f;
  for (int s = 0; s < 40; ++s) {
    br.plate(d, x0, x0 + 2.f, 6, 26, 12, 30.f);
    g.set_bristles(br.field());
    g.step(p.dt);
    x0 += 0.5f;
  }
  const auto after = g.window().paint().to_host();
  int dried = 0;
  for (size_t c = 0; c < after[0].size(); ++c) {
    if (f[5][c] < 1.f) continue;
    ++dried;
    for (int q = 0; q < kPaintFieldCount; ++q) ASSERT_EQ(after[size_t(q)][c], f[size_t(q)][c]) << "field " << q;
  }
  EXPECT_GT(dried, 500);
  // The wet paint did move (the test is not vacuous).
  EXPECT_GT(centroid(d, after[0]).x, centroid(d, f[0]).x + 0.2f);
}

TEST_F(GridStepTest, DryingMakesPaintSolid) {
  TileStore canvas(device_, CanvasDims{128, 128, 64});
  GridParams p;
  p.dry_rate = 3.f;  // fully dry in a third of a second
  Grid g(canvas, p, Int3{32, 32, 16}, Int3{0, 0, 0});
  paint_cells(g, [](int, int, int k) { return k < 4 ? 1.f : 0.f; });
  g.dry(0.1f);
  const auto dry1 = g.window().paint().dryness.to_host();
  const GridDims d = g.dims();
  EXPECT_NEAR(dry1[size_t(d.cell(3, 3, 1))], 0.3f, 1e-6f);
  EXPECT_EQ(dry1[size_t(d.cell(3, 3, 8))], 0.f);  // no paint, no dryness
  for (int s = 0; s < 4; ++s) g.dry(0.1f);
  g.classify();
  std::vector<uint8_t> cls(size_t(d.cells()));
  mem::copy_to_host(device_, cls.data(), g.view().cls, cls.size());
  EXPECT_EQ(cls[size_t(d.cell(3, 3, 1))], kCellSolid);
  EXPECT_EQ(cls[size_t(d.cell(3, 3, 8))], kCellAir);
}

TEST_F(GridStepTest, LetItDryMakesTheWholeCanvasSolid) {
  TileStore canvas(device_, CanvasDims{128, 128, 64});
  Grid g(canvas, GridParams{}, Int3{32, 32, 16}, Int3{8, 8, 0});
  paint_cells(g, [](int, int, int k) { return k < 4 ? 1.f : 0.f; });
  g.window().flush();
  canvas.dry_all();
  g.window().reload();
  g.classify();
  const GridDims d = g.dims();
  std::vector<uint8_t> cls(size_t(d.cells()));
  mem::copy_to_host(device_, cls.data(), g.view().cls, cls.size());
  for (int k = 0; k < 4; ++k) EXPECT_EQ(cls[size_t(d.cell(5, 7, k))], kCellSolid);
  EXPECT_EQ(cls[size_t(d.cell(5, 7, 4))], kCellAir);
}

TEST_F(GridStepTest, ViscousSolveConvergesForTheStiffestPaint) {
  TileStore canvas(device_, CanvasDims{128, 128, 64});
  GridParams p;
  p.yield_stress_stiff = 1e4f;  // the table's top: unyielded mu = tau_y m = 1e6 Pa s, nu dt ~ 4e8 cells^2
  p.consistency_stiff = 1e5f;
  Grid g(canvas, p, Int3{32, 32, 16}, Int3{0, 0, 0});
  paint_cells(g, [](int, int, int k) { return k < 10 ? 1.f : 0.f; }, /*oil=*/0.f);
  g.classify();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-100.f, 100.f);
  for (int c = 0; c < 3; ++c) {
    std::vector<float> v(size_t(g.dims().faces(c)));
    for (auto& x : v) x = u(rng);
    g.window().velocity(c).copy_from_host(v);
  }
  const float before = g.max_fluid_speed();
  g.rheology();
  g.apply_viscosity(p.dt);
  const float after = g.max_fluid_speed();
  EXPECT_TRUE(std::isfinite(after));
  EXPECT_LE(g.stats().viscosity_residual, p.viscosity_tolerance);
  EXPECT_LT(g.stats().viscosity_iterations, p.viscosity_max_iterations);
  EXPECT_GT(g.stats().viscosity_faces, 3 * 30 * 30 * 9);
  EXPECT_LT(after, 0.5f * before);  // a no-slip floor and a random field: diffusion damps it
  std::printf("[ viscosity ] stiffest paint: %d faces, %d CG iterations, residual %.2e\n",
              g.stats().viscosity_faces, g.stats().viscosity_iterations, g.stats().viscosity_residual);
}

TEST_F(GridStepTest, AdvectionMassDriftIsCorrected) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  for (bool correct : {false, true}) {
    GridParams p;
    p.mass_correction = correct;
    Grid g(canvas, p, Int3{64, 32, 24}, Int3{32, 32, 0});
    const GridDims d = g.dims();
    paint_cells(g, [](int i, int j, int k) {
      return (i >= 20 && i < 44 && j >= 8 && j < 24) ? std::clamp(4.5f - float(k), 0.f, 1.f) : 0.f;
    });
    const double m0 = sum(host_density(g));
    HostBristles br(device_, d.cells());
    float x0 = 14.f;
    double drift = 0;
    for (int s = 0; s < 60; ++s) {
      br.plate(d, x0, x0 + 2.f, 4, 28, 14, 30.f);
      g.set_bristles(br.field());
      g.step(p.dt);
      drift += g.stats().advect_change + g.stats().advect_correction;
      x0 += 0.5f;
    }
    const double m1 = sum(host_density(g));
    EXPECT_NEAR(m1 - m0, drift, 1e-4 * m0);  // the books explain the change
    if (correct) EXPECT_NEAR(m1, m0, 1e-5 * m0);
    RecordProperty(correct ? "drift_corrected" : "drift_uncorrected", std::to_string((m1 - m0) / m0));
    std::printf("[ mass ] correction %s: relative change over 1 s of stroke %.3e\n", correct ? "on " : "off",
                (m1 - m0) / m0);
  }
}

}  // namespace wb::test
