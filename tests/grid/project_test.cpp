// Pressure projection (paper §4.2, Algorithm 1, Eq. 3-7): divergence reduction on random
// and real windows, convergence of every solver to the CG answer, the equivalences of
// Figure 6's caption (alpha = 0 is Jacobi), and the Chebyshev rho estimate.
#include <cmath>
#include <random>

#include "backend_fixture.h"
#include "core/grid/solver_study.h"
#include "grid/grid_test_util.h"

namespace wb::test {

class ProjectTest : public BackendTest {
 protected:
  /// A random window: liquid, air, dried cells, partial bristles and random velocity.
  void randomise(Grid& g, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const GridDims d = g.dims();
    Fields f = empty_fields(g);
    for (int64_t c = 0; c < d.cells(); ++c) {
      int i, j, k;
      d.decompose_cell(c, i, j, k);
      const float r = u(rng);
      // Mostly liquid near the floor, air above; a few dried cells.
      const bool low = k < d.nz / 2;
      f[0][size_t(c)] = (low ? r < 0.9f : r < 0.2f) ? 1.f : 0.f;
      f[4][size_t(c)] = u(rng);
      if (f[0][size_t(c)] > 0 && u(rng) < 0.05f) f[5][size_t(c)] = 1.f;
    }
    g.window().paint().from_host(f);
    psi_host_.assign(size_t(d.cells()), 0.f);
    for (auto& p : psi_host_) p = u(rng) < 0.1f ? u(rng) : 0.f;
    for (int c = 0; c < 3; ++c) {
      std::vector<float> v(size_t(d.faces(c)));
      for (auto& x : v) x = 2.f * u(rng) - 1.f;
      g.window().velocity(c).copy_from_host(v);
    }
  }
  std::vector<float> psi_host_;
};

TEST_F(ProjectTest, ReducesDivergenceOnRandomWindows) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  for (unsigned seed = 1; seed <= 3; ++seed) {
    GridParams p;
    p.projection_norms = true;
    Grid g(canvas, p, Int3{32, 32, 16}, Int3{16, 16, 0});
    randomise(g, seed);
    HostBristles br(device_, g.dims().cells());
    br.psi.copy_from_host(psi_host_);
    br.vx.copy_from_host(psi_host_);  // some bristle velocity where psi > 0
    br.vy.fill_zero();
    br.vz.fill_zero();
    g.set_bristles(br.field());
    g.classify();
    const double before = g.divergence_norm();
    g.project(g.params().dt);
    const double after = g.divergence_norm();
    // The projection's own books agree with a fresh divergence of the velocity it wrote.
    EXPECT_NEAR(g.stats().residual_norm, after, 1e-3 * before);
    // Documented in docs/GRID.md: 6 sweeps (L = 3, alpha = 1) cut ||div|| by >= 4x on these.
    EXPECT_LT(after, before / 4.0) << "seed " << seed << ": " << before << " -> " << after;
  }
}

TEST_F(ProjectTest, ReducesDivergenceOnRealWindow) {
  StudyScene scene(device_, 64);
  scene.prepare_system();
  Grid& g = scene.grid();
  const double before = g.divergence_norm();
  ASSERT_GT(before, 0.0);
  g.project(g.params().dt);
  const double after = g.divergence_norm();
  // Documented in docs/GRID.md: >= 1.5x on the brush window (smooth, brush-driven divergence).
  EXPECT_LT(after, before / 1.5) << before << " -> " << after;
}

TEST_F(ProjectTest, EverySolverConvergesToConjugateGradients) {
  StudyScene scene(device_, 32);
  scene.prepare_system();
  Grid& g = scene.grid();
  const HostPoisson sys = download_system(g);
  int iters = 0;
  const std::vector<double> xstar = cg_solve(sys, 1e-10, 100000, &iters);
  EXPECT_LT(iters, 100000);
  const float rho = estimate_jacobi_rho(device_, g.poisson(), 300, g.solver_scratch(), g.workspace());
  EXPECT_GT(rho, 0.5f);
  EXPECT_LT(rho, 1.f);
  DeviceBuffer<float> x(device_, size_t(g.dims().cells()));
  struct Case {
    PressureSolver kind;
    int sweeps;
    float alpha;
    double tol;
  };
  for (const Case& cs : {Case{PressureSolver::Chebyshev, 3000, 1.f, 1e-4}, Case{PressureSolver::Jacobi, 20000, 1.f, 1e-3},
                         Case{PressureSolver::FixedPoint, 20000, 1.f, 1e-3},
                         Case{PressureSolver::FixedPoint, 20000, 0.5f, 1e-3}}) {
    SolverConfig cfg;
    cfg.kind = cs.kind;
    cfg.sweeps = cs.sweeps;
    cfg.alpha = cs.alpha;
    cfg.rho = rho;
    solve_pressure(device_, g.poisson(), g.rhs().data(), x.data(), cfg, g.solver_scratch());
    const double err = relative_error(sys, x.to_host(), xstar);
    EXPECT_LT(err, cs.tol) << "solver " << int(cs.kind) << " alpha " << cs.alpha;
  }
}

TEST_F(ProjectTest, FixedPointWithAlphaZeroIsJacobi) {
  // Figure 6 caption: alpha = 0 is plain Jacobi (two sweeps per iteration).
  StudyScene scene(device_, 32);
  scene.prepare_system();
  Grid& g = scene.grid();
  DeviceBuffer<float> a(device_, size_t(g.dims().cells())), b(device_, size_t(g.dims().cells()));
  SolverConfig cfg;
  cfg.kind = PressureSolver::FixedPoint;
  cfg.alpha = 0.f;
  cfg.sweeps = 6;
  solve_pressure(device_, g.poisson(), g.rhs().data(), a.data(), cfg, g.solver_scratch());
  cfg.kind = PressureSolver::Jacobi;
  solve_pressure(device_, g.poisson(), g.rhs().data(), b.data(), cfg, g.solver_scratch());
  const auto ha = a.to_host(), hb = b.to_host();
  double num = 0, den = 0;
  for (size_t i = 0; i < ha.size(); ++i) {
    num += double(ha[i] - hb[i]) * (ha[i] - hb[i]);
    den += double(hb[i]) * hb[i];
  }
  ASSERT_GT(den, 0.0);
  EXPECT_LT(std::sqrt(num / den), 1e-5);
}

TEST_F(ProjectTest, ResidualIsTheDivergenceOfTheProjectedVelocity) {
  // Algorithm 1 runs in pressure space here; its residual must be what the velocity update
  // leaves as divergence (u -= grad p with face fractions).
  StudyScene scene(device_, 32);
  scene.prepare_system();
  Grid& g = scene.grid();
  g.params().jacobi_L = 3;
  g.params().projection_norms = true;
  g.project(g.params().dt);
  const double after = g.divergence_norm(g.params().dt);
  EXPECT_NEAR(after, g.stats().residual_norm, 1e-4 * g.stats().rhs_norm);
  EXPECT_LT(after, g.stats().rhs_norm);
}

}  // namespace wb::test
