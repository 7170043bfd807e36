// Solver study (paper §4.2, Figure 6): see solver_study.h.
#include "core/grid/solver_study.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/exec/memory.h"
#include "core/grid/project_kernels.h"

namespace wb {

namespace {
uint32_t hash3(int i, int j, int k, unsigned seed) {
  uint32_t h = uint32_t(i) * 73856093u ^ uint32_t(j) * 19349663u ^ uint32_t(k) * 83492791u ^ seed * 2654435761u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return h;
}
float unit(uint32_t h) { return float(h & 0xFFFFFF) / float(0x1000000); }
Int3 study_dims(int size, StudySceneKind kind) {
  return kind == StudySceneKind::kCube ? Int3{size, size, size} : Int3{size, size, std::max(size / 4, 8)};
}
}  // namespace

StudyScene::StudyScene(const Device& device, int size, unsigned seed, StudySceneKind kind)
    : kind_(kind),
      canvas_(device, CanvasDims{std::max(512, size * 2), std::max(512, size * 2), std::max(64, size)}),
      grid_(canvas_, GridParams{}, study_dims(size, kind), Int3{64, 64, 0}) {
  WB_REQUIRE(size >= 16 && size <= 512, "solver study: --size must be in [16, 512]");
  WB_REQUIRE(kind == StudySceneKind::kBrushWindow || size <= 128, "solver study: cube scene needs --size <= 128");
  const Int3 n = study_dims(size, kind);
  const int64_t cells = int64_t(n.x) * n.y * n.z;
  // Paint layer: a wavy layer about size/16 cells thick (at least 3), with ridges.
  std::vector<std::vector<float>> f(kPaintFieldCount, std::vector<float>(size_t(cells), 0.f));
  std::vector<float> psi(size_t(cells), 0.f), vx(size_t(cells), 0.f), vy(size_t(cells), 0.f), vz(size_t(cells), 0.f);
  const float base = std::max(3.f, float(size) / 16.f);
  const float cx = 0.5f * n.x, cy = 0.5f * n.y, ax = 0.22f * n.x, ay = 0.14f * n.y;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const size_t c = size_t((int64_t(k) * n.y + j) * n.x + i);
        const float h = base * (1.f + 0.35f * std::sin(0.31f * i) * std::cos(0.23f * j)) + 1.5f * unit(hash3(i, j, 0, seed));
        const float fill = kind == StudySceneKind::kCube ? 1.f : std::clamp(h - float(k), 0.f, 1.f);
        f[0][c] = fill;
        f[1][c] = fill > 0 ? 0.8f : 0.f;
        f[2][c] = fill > 0 ? 0.2f : 0.f;
        f[3][c] = fill > 0 ? 0.1f : 0.f;
        f[4][c] = fill > 0 ? 0.3f : 0.f;
        // Pressed brush: a tuft splayed over an ellipse, bristles denser near the canvas,
        // up to about twice the layer thickness, moving along +x and slightly down.
        const float ex = (float(i) + 0.5f - cx) / ax, ey = (float(j) + 0.5f - cy) / ay;
        const float r2 = ex * ex + ey * ey;
        const float top = 2.f * base * (1.f - 0.5f * r2) + 1.f;
        if (kind == StudySceneKind::kBrushWindow && r2 < 1.f && float(k) < top) {
          psi[c] = std::min(1.f, 0.45f + 0.5f * unit(hash3(i, j, k, seed + 7)));
          vx[c] = 240.f;
          vy[c] = 30.f * ey;
          vz[c] = -20.f;
        }
      }
  grid_.window().paint().from_host(f);
  grid_.window().flush();
  psi_ = DeviceBuffer<float>(device, size_t(cells));
  vx_ = DeviceBuffer<float>(device, size_t(cells));
  vy_ = DeviceBuffer<float>(device, size_t(cells));
  vz_ = DeviceBuffer<float>(device, size_t(cells));
  psi_.copy_from_host(psi);
  vx_.copy_from_host(vx);
  vy_.copy_from_host(vy);
  vz_.copy_from_host(vz);
  grid_.set_bristles(bristles());
  if (kind == StudySceneKind::kCube) {
    for (int c = 0; c < 3; ++c) {
      std::vector<float> v(size_t(grid_.dims().faces(c)));
      for (size_t f = 0; f < v.size(); ++f) v[f] = 2.f * unit(hash3(int(f), c, 1, seed)) - 1.f;
      grid_.window().velocity(c).copy_from_host(v);
    }
  }
}

BristleField StudyScene::bristles() { return BristleField{psi_.data(), vx_.data(), vy_.data(), vz_.data()}; }

void StudyScene::prepare_system(int warmup_steps) {
  const float dt = grid_.params().dt;
  if (kind_ == StudySceneKind::kCube) {  // the random velocity's divergence, nothing else
    grid_.classify();
    grid_.compute_rhs();
    return;
  }
  for (int s = 0; s < warmup_steps; ++s) grid_.step(dt);
  grid_.classify();
  grid_.advect(dt);
  grid_.classify();
  grid_.rheology();
  grid_.add_external_forces(dt);
  grid_.apply_viscosity(dt);
  grid_.compute_rhs(dt);
}

PoissonView HostPoisson::view() const {
  PoissonView v{};
  v.d = d;
  v.cls = cls.data();
  for (int c = 0; c < 3; ++c) v.theta[c] = theta[c].data();
  return v;
}

int64_t HostPoisson::liquid_cells() const { return std::count(cls.begin(), cls.end(), uint8_t(kCellLiquid)); }

HostPoisson download_system(Grid& grid) {
  HostPoisson h;
  const GridView v = grid.view();
  h.d = v.d;
  h.cls.resize(size_t(v.d.cells()));
  mem::copy_to_host(grid.device(), h.cls.data(), v.cls, h.cls.size());
  for (int c = 0; c < 3; ++c) {
    h.theta[c].resize(size_t(v.d.faces(c)));
    mem::copy_to_host(grid.device(), h.theta[c].data(), v.theta[c], h.theta[c].size() * sizeof(float));
  }
  h.b = grid.rhs().to_host();
  return h;
}

namespace {
void apply_host(const HostPoisson& s, const std::vector<double>& x, std::vector<double>& out) {
  const PoissonView v = s.view();
  const int64_t n = s.d.cells();
#pragma omp parallel for schedule(static)
  for (int64_t c = 0; c < n; ++c) {
    int i, j, k;
    v.d.decompose_cell(c, i, j, k);
    out[size_t(c)] = poisson_apply(v, x.data(), c, i, j, k);
  }
}
double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double acc = 0;
  const int64_t n = int64_t(a.size());
#pragma omp parallel for reduction(+ : acc) schedule(static)
  for (int64_t i = 0; i < n; ++i) acc += a[size_t(i)] * b[size_t(i)];
  return acc;
}
std::vector<double> diagonal(const HostPoisson& s) {
  const PoissonView v = s.view();
  std::vector<double> d(size_t(s.d.cells()), 0.0), zero(size_t(s.d.cells()), 0.0);
  for (int64_t c = 0; c < s.d.cells(); ++c) {
    if (s.cls[size_t(c)] != kCellLiquid) continue;
    int i, j, k;
    s.d.decompose_cell(c, i, j, k);
    double diag, off;
    poisson_row(v, zero.data(), i, j, k, diag, off);
    d[size_t(c)] = diag;
  }
  return d;
}
}  // namespace

namespace {
/// Jacobi-preconditioned CG on A x = rhs (rhs on liquid cells), double precision.
std::vector<double> cg_core(const HostPoisson& s, const std::vector<double>& diag, const std::vector<double>& rhs,
                            double tol, int max_iter, int* iterations) {
  const size_t n = size_t(s.d.cells());
  std::vector<double> x(n, 0.0), r(n), z(n), p(n), q(n);
  for (size_t i = 0; i < n; ++i) r[i] = (s.cls[i] == kCellLiquid && diag[i] > 1e-6) ? rhs[i] : 0.0;
  const double bnorm = std::sqrt(dot(r, r));
  auto precondition = [&] {
    for (size_t i = 0; i < n; ++i) z[i] = diag[i] > 1e-6 ? r[i] / diag[i] : 0.0;
  };
  precondition();
  p = z;
  double rz = dot(r, z);
  int it = 0;
  for (; it < max_iter && bnorm > 0; ++it) {
    if (std::sqrt(dot(r, r)) <= tol * bnorm) break;
    apply_host(s, p, q);
    const double a = rz / dot(p, q);
    for (size_t i = 0; i < n; ++i) {
      x[i] += a * p[i];
      r[i] -= a * q[i];
    }
    precondition();
    const double rz2 = dot(r, z);
    const double beta = rz2 / rz;
    rz = rz2;
    for (size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
  }
  if (iterations) *iterations = it;
  return x;
}
}  // namespace

std::vector<double> cg_solve(const HostPoisson& s, double tol, int max_iter, int* iterations) {
  const std::vector<double> rhs(s.b.begin(), s.b.end());
  return cg_core(s, diagonal(s), rhs, tol, max_iter, iterations);
}

double jacobi_rho_by_inverse_iteration(const HostPoisson& s, int iters) {
  // rho(D^-1 R) = 1 - lambda_min of A x = lambda D x; inverse iteration x <- A^-1 D x with
  // CG solves, Rayleigh quotient x'Ax / x'Dx.
  const std::vector<double> diag = diagonal(s);
  const size_t n = diag.size();
  std::vector<double> x(n, 0.0), dx(n), ax(n);
  for (size_t i = 0; i < n; ++i) x[i] = (s.cls[i] == kCellLiquid && diag[i] > 1e-6) ? 1.0 + 0.1 * unit(hash3(int(i), 0, 0, 3)) : 0.0;
  double lambda = 1.0;
  for (int it = 0; it < iters; ++it) {
    for (size_t i = 0; i < n; ++i) dx[i] = diag[i] * x[i];
    x = cg_core(s, diag, dx, 1e-8, 100000, nullptr);
    apply_host(s, x, ax);
    double xax = 0, xdx = 0;
    for (size_t i = 0; i < n; ++i) {
      xax += x[i] * ax[i];
      xdx += x[i] * diag[i] * x[i];
    }
    if (xdx <= 0) return 0.0;
    lambda = xax / xdx;
    const double inv = 1.0 / std::sqrt(xdx);
    for (double& v : x) v *= inv;
  }
  return 1.0 - lambda;
}

double relative_error(const HostPoisson& s, const std::vector<float>& x, const std::vector<double>& ref) {
  double num = 0, den = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (s.cls[i] != kCellLiquid) continue;
    const double e = double(x[i]) - ref[i];
    num += e * e;
    den += ref[i] * ref[i];
  }
  return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

double relative_residual(const HostPoisson& s, const std::vector<float>& x) {
  std::vector<double> xd(x.begin(), x.end()), ax(x.size());
  apply_host(s, xd, ax);
  double num = 0, den = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    if (s.cls[i] != kCellLiquid) continue;
    const double r = double(s.b[i]) - ax[i];
    num += r * r;
    den += double(s.b[i]) * double(s.b[i]);
  }
  return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

std::string SolverStudyResult::best_at(int sweeps) const {
  std::string best;
  double e = std::numeric_limits<double>::infinity();
  for (const SolverCurve& c : curves) {
    if (sweeps >= int(c.error.size()) || std::isnan(c.error[size_t(sweeps)])) continue;
    if (c.error[size_t(sweeps)] < e) {
      e = c.error[size_t(sweeps)];
      best = c.name;
    }
  }
  return best;
}

SolverStudyResult run_solver_study(const Device& device, int size, int sweeps, unsigned seed, StudySceneKind kind) {
  WB_REQUIRE(sweeps >= 0 && sweeps <= 10000, "solver study: --sweeps must be in [0, 10000]");
  StudyScene scene(device, size, seed, kind);
  scene.prepare_system();
  Grid& grid = scene.grid();
  const HostPoisson sys = download_system(grid);
  SolverStudyResult res;
  res.scene = kind == StudySceneKind::kCube ? "cube" : "brush-window";
  res.nx = sys.d.nx;
  res.ny = sys.d.ny;
  res.nz = sys.d.nz;
  res.liquid_cells = sys.liquid_cells();
  const std::vector<double> xstar = cg_solve(sys, 1e-10, 100000, &res.cg_iterations);
  {
    std::vector<float> xf(xstar.begin(), xstar.end());
    std::vector<double> ax(xstar.size());
    double num = 0, den = 0;
    apply_host(sys, xstar, ax);
    for (size_t i = 0; i < ax.size(); ++i)
      if (sys.cls[i] == kCellLiquid) {
        num += (sys.b[i] - ax[i]) * (sys.b[i] - ax[i]);
        den += double(sys.b[i]) * sys.b[i];
      }
    res.cg_relative_residual = den > 0 ? std::sqrt(num / den) : 0;
  }
  const PoissonView s = grid.poisson();
  const int64_t n = s.d.cells();
  DeviceBuffer<float> x(device, size_t(n));
  SolverScratch& scratch = grid.solver_scratch();
  res.rho_estimate = estimate_jacobi_rho(device, s, 300, scratch, grid.workspace());

  std::vector<float> host(static_cast<size_t>(n));
  auto run = [&](const std::string& name, float param, SolverConfig cfg, bool with_residual) {
    SolverCurve curve;
    curve.name = name;
    curve.parameter = param;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    curve.error.assign(size_t(sweeps) + 1, nan);
    curve.residual.assign(size_t(sweeps) + 1, nan);
    std::fill(host.begin(), host.end(), 0.f);
    curve.error[0] = relative_error(sys, host, xstar);
    curve.residual[0] = relative_residual(sys, host);
    cfg.sweeps = sweeps;
    solve_pressure(device, s, grid.rhs().data(), x.data(), cfg, scratch, [&](int k, const float* xk) {
      mem::copy_to_host(device, host.data(), xk, host.size() * sizeof(float));
      curve.error[size_t(k)] = relative_error(sys, host, xstar);
      if (with_residual) curve.residual[size_t(k)] = relative_residual(sys, host);
    });
    return curve;
  };

  SolverConfig cfg;
  cfg.kind = PressureSolver::Jacobi;
  res.curves.push_back(run("jacobi", 1.f, cfg, true));
  // Weighted Jacobi: the omega with the smallest error after six sweeps (the paper's budget).
  const int probe = std::min(6, sweeps);
  double best_e = std::numeric_limits<double>::infinity();
  for (int q = 0; q <= 10; ++q) {
    cfg.kind = PressureSolver::WeightedJacobi;
    cfg.omega = 0.5f + 0.05f * float(q);
    SolverCurve c = run("weighted_jacobi", cfg.omega, cfg, false);
    if (c.error[size_t(probe)] < best_e) {
      best_e = c.error[size_t(probe)];
      res.best_omega = cfg.omega;
    }
  }
  cfg.kind = PressureSolver::WeightedJacobi;
  cfg.omega = res.best_omega;
  res.curves.push_back(run("weighted_jacobi", res.best_omega, cfg, true));
  cfg.kind = PressureSolver::Chebyshev;
  cfg.rho = res.rho_estimate;
  res.curves.push_back(run("chebyshev", res.rho_estimate, cfg, true));
  // The asymptotically optimal rho (the true spectral radius), as the paper's Figure 6 uses.
  res.rho_exact = float(jacobi_rho_by_inverse_iteration(sys, 12));
  cfg.rho = std::min(res.rho_exact, 0.999999f);
  res.curves.push_back(run("chebyshev_exact_rho", cfg.rho, cfg, true));
  for (float a : {0.f, 0.5f, 1.f}) {
    cfg.kind = PressureSolver::FixedPoint;
    cfg.alpha = a;
    char name[32];
    std::snprintf(name, sizeof(name), "fixed_point_a%g", double(a));
    res.curves.push_back(run(name, a, cfg, true));
  }
  return res;
}

std::string solver_study_text(const SolverStudyResult& r) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line),
                "# system: %s, %d x %d x %d cells, %lld liquid cells; x* by Jacobi-preconditioned CG in double, "
                "%d iterations, relative residual %.2e\n",
                r.scene.c_str(), r.nx, r.ny, r.nz, (long long)r.liquid_cells, r.cg_iterations, r.cg_relative_residual);
  out += line;
  std::snprintf(line, sizeof(line),
                "# rho(D^-1 R): %.5f by 300 power sweeps (\"chebyshev\"), %.6f by inverse iteration "
                "(\"chebyshev_exact_rho\"); best weighted-Jacobi omega at 6 sweeps: %.2f\n",
                double(r.rho_estimate), double(r.rho_exact), double(r.best_omega));
  out += line;
  out += "# error = ||x - x*|| / ||x*||, residual = ||b - A x|| / ||b||; fixed point: one iterate per 2 sweeps\n";
  out += "sweeps";
  for (const auto& c : r.curves) {
    std::snprintf(line, sizeof(line), " %18s_err %18s_res", c.name.c_str(), c.name.c_str());
    out += line;
  }
  out += "\n";
  const size_t rows = r.curves.empty() ? 0 : r.curves[0].error.size();
  for (size_t k = 0; k < rows; ++k) {
    std::snprintf(line, sizeof(line), "%6zu", k);
    out += line;
    for (const auto& c : r.curves) {
      if (std::isnan(c.error[k]))
        std::snprintf(line, sizeof(line), " %22s %22s", "-", "-");
      else
        std::snprintf(line, sizeof(line), " %22.6f %22.6f", c.error[k], c.residual[k]);
      out += line;
    }
    out += "\n";
  }
  for (int k : {2, 4, 6}) {
    if (size_t(k) >= rows) break;
    std::snprintf(line, sizeof(line), "# smallest error after %d sweeps: %s\n", k, r.best_at(k).c_str());
    out += line;
  }
  return out;
}

std::string solver_study_json(const SolverStudyResult& r) {
  nlohmann::json j;
  j["scene"] = r.scene;
  j["window"] = {r.nx, r.ny, r.nz};
  j["liquid_cells"] = r.liquid_cells;
  j["cg_iterations"] = r.cg_iterations;
  j["cg_relative_residual"] = r.cg_relative_residual;
  j["rho_estimate"] = r.rho_estimate;
  j["rho_exact"] = r.rho_exact;
  j["best_omega"] = r.best_omega;
  auto arr = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(std::isnan(x) ? nlohmann::json(nullptr) : nlohmann::json(x));
    return a;
  };
  for (const auto& c : r.curves) {
    nlohmann::json cj;
    cj["name"] = c.name;
    cj["parameter"] = c.parameter;
    cj["error"] = arr(c.error);
    cj["residual"] = arr(c.residual);
    j["curves"].push_back(cj);
  }
  for (int k : {2, 4, 6}) j["best_at"][std::to_string(k)] = r.best_at(k);
  return j.dump(2);
}

}  // namespace wb
