// Solver study (paper §4.2, Figure 6, Eq. 3-7): builds a representative pressure system
// from a real window (a paint layer on the canvas with a pressed, moving brush inside it),
// solves it to 1e-10 by conjugate gradients in double, and records the error
// ||x - x*|| / ||x*|| and the residual ||b - A x|| / ||b|| of Jacobi, weighted Jacobi (best
// omega), Chebyshev and the fixed-point method (alpha = 0, 0.5, 1) after each sweep.
#pragma once
#include <string>
#include <vector>

#include "core/canvas/tile_store.h"
#include "core/grid/grid.h"

namespace wb {

/// kBrushWindow: a window of size x size x max(size/4, 8) cells with a paint layer and a pressed
/// brush (the systems the simulator solves). kCube: size^3 cells all liquid, closed sides and
/// floor, open top, random velocity (the paper's "32^3 Poisson" check of Figure 6).
enum class StudySceneKind { kBrushWindow, kCube };

class StudyScene {
 public:
  StudyScene(const Device& device, int size, unsigned seed = 1, StudySceneKind kind = StudySceneKind::kBrushWindow);
  /// Runs `warmup_steps` full grid steps with the brush moving, then the stages of one more
  /// step up to the projection, leaving its system in grid().poisson() / grid().rhs().
  void prepare_system(int warmup_steps = 3);
  Grid& grid() { return grid_; }
  BristleField bristles();

 private:
  StudySceneKind kind_;
  TileStore canvas_;
  Grid grid_;
  DeviceBuffer<float> psi_, vx_, vy_, vz_;
};

/// Host copy of a pressure system.
struct HostPoisson {
  GridDims d{};
  std::vector<uint8_t> cls;
  std::vector<float> theta[3];
  std::vector<float> b;
  PoissonView view() const;
  int64_t liquid_cells() const;
};
HostPoisson download_system(Grid& grid);

/// Conjugate gradients in double on the host (Jacobi-preconditioned), to ||r|| <= tol ||b||.
std::vector<double> cg_solve(const HostPoisson& s, double tol, int max_iter, int* iterations = nullptr);
/// rho(D^-1 R) = 1 - lambda_min(D^-1 A) by inverse iteration (iters CG solves in double).
double jacobi_rho_by_inverse_iteration(const HostPoisson& s, int iters);
/// ||x - ref|| / ||ref|| and ||b - A x|| / ||b|| over liquid cells.
double relative_error(const HostPoisson& s, const std::vector<float>& x, const std::vector<double>& ref);
double relative_residual(const HostPoisson& s, const std::vector<float>& x);

struct SolverCurve {
  std::string name;  ///< "jacobi", "weighted_jacobi", "chebyshev", "fixed_point_a0" ...
  float parameter = 0;  ///< omega, rho or alpha
  std::vector<double> error;     ///< index = sweeps; NaN where the method has no iterate
  std::vector<double> residual;  ///< same
};

struct SolverStudyResult {
  std::string scene;
  int nx = 0, ny = 0, nz = 0;
  int64_t liquid_cells = 0;
  int cg_iterations = 0;
  double cg_relative_residual = 0;
  float rho_estimate = 0;  ///< power iteration, 300 sweeps (a practical estimate, from below)
  float rho_exact = 0;     ///< inverse iteration with CG solves (the asymptotically optimal value)
  float best_omega = 1;
  std::vector<SolverCurve> curves;
  /// Name of the curve with the smallest error at `sweeps` (ties broken by order).
  std::string best_at(int sweeps) const;
};

SolverStudyResult run_solver_study(const Device& device, int size, int sweeps, unsigned seed = 1,
                                   StudySceneKind kind = StudySceneKind::kBrushWindow);
std::string solver_study_text(const SolverStudyResult& r);
std::string solver_study_json(const SolverStudyResult& r);

}  // namespace wb
