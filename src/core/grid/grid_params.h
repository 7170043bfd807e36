// Parameters of the grid-based liquid stage (paper §4.2, Algorithm 1, Eq. 3-7).
// One POD, passed by value to the stage drivers. Units: lengths in canvas cells
// (1 cell = 0.2 mm), velocities in cells/s, time in s.
#pragma once
#include <cmath>

#include "core/math/vec.h"

namespace wb {

/// Pressure solver behind Grid::project(). All run a fixed number of Jacobi-type sweeps.
enum class PressureSolver : int {
  FixedPoint = 0,      ///< Algorithm 1 / Eq. 3: L iterations of two Jacobi sweeps restarted from alpha * y
  Jacobi = 1,          ///< plain Jacobi (Eq. 7 with omega = 1)
  WeightedJacobi = 2,  ///< Eq. 7 with omega = jacobi_omega
  Chebyshev = 3,       ///< Chebyshev semi-iteration, Eq. 6 (Golub & Van Loan 1996 §10.1.5)
};

struct GridParams {
  // --- time ---
  /// Step length. Default 1/60 s, range (0, 0.1] s. DESIGN "Units and scale".
  float dt = 1.f / 60.f;

  // --- pressure projection (§4.2, Algorithm 1) ---
  PressureSolver solver = PressureSolver::FixedPoint;
  /// Fixed-point iterations L of Algorithm 1 (each = two Jacobi sweeps). Default 3, range [0, 1000]. Alg. 1.
  int jacobi_L = 3;
  /// Restart weight alpha of Algorithm 1 / Eq. 3-5. Default 1, range [0, 1]. §4.2 ("simply set to 1").
  float alpha = 1.f;
  /// Sweeps of the Jacobi / weighted Jacobi / Chebyshev solvers. Default 6 (= 2L), range [0, 10000].
  int solver_sweeps = 6;
  /// Weight of weighted Jacobi, Eq. 7. Default 0.8 (dimensionless), range (0, 1].
  float jacobi_omega = 0.8f;
  /// Spectral-radius estimate rho of D^-1 R for Chebyshev (Eq. 6); <= 0: estimated by power
  /// iteration (chebyshev_power_iterations sweeps) at each projection. Default 0, range [0, 1).
  float chebyshev_rho = 0.f;
  /// Power-iteration sweeps of the rho estimate. Default 30, range [1, 1000].
  int chebyshev_power_iterations = 30;

  // --- rheology: regularised Herschel-Bulkley (docs/GRID.md "Rheology") ---
  // tau = tau_y + K gamma_dot^n above the yield stress. The oil fraction moves each parameter
  // between the stiff end member (oil 0: tube paint with little binder) and the oily one (oil 1:
  // the binder itself): tau_y and K geometrically, n linearly (rheology.h).
  /// Yield stress at oil 0, Pa. Default 300, range [0, 1e4]. Tube oil paints: tens to hundreds of Pa.
  float yield_stress_stiff = 300.f;
  /// Yield stress at oil 1, Pa. Default 0.1, range [0, 1e4]. Linseed oil has none; a trace keeps
  /// the geometric interpolation defined.
  float yield_stress_oily = 0.1f;
  /// Consistency K at oil 0, Pa s^n. Default 30, range (0, 1e5].
  float consistency_stiff = 30.f;
  /// Consistency K at oil 1, Pa s^n. Default 0.05 (linseed oil, about 0.05 Pa s), range (0, 1e5].
  float consistency_oily = 0.05f;
  /// Flow index n at oil 0. Default 0.5 (strongly shear-thinning), range (0, 1].
  float flow_index_stiff = 0.5f;
  /// Flow index n at oil 1. Default 1 (the oil is Newtonian), range (0, 1].
  float flow_index_oily = 1.f;
  /// Papanastasiou regularisation m, s: below the critical strain rate 1/m the paint is a
  /// liquid of viscosity tau_y m + K m^(1-n) (unyielded: it creeps at stress / that). Default 1e4
  /// (a 3 mm ridge of stiff paint creeps about a micrometre in 2 s, docs/GRID.md), range [1, 1e5].
  float regularisation = 1e4f;
  /// Paint density rho0, kg/m^3 (mu / rho0 is the kinematic viscosity). Default 1000 (§5.1).
  float rho0 = 1000.f;
  /// Cell edge, m. Default 2e-4 (0.2 mm, DESIGN "Units and scale").
  float cell_size = 2e-4f;
  /// Relative residual the viscous solve stops at: sqrt(r D^-1 r / b D^-1 b) (Jacobi-preconditioned
  /// CG). Default 1e-3, range [1e-7, 1].
  float viscosity_tolerance = 1e-3f;
  /// Work bound of the viscous solve, CG iterations per step. Default 300, range [0, 10000]
  /// (0 = no viscosity). GridStats reports the iterations used and the residual reached.
  int viscosity_max_iterations = 300;

  // --- external forces ---
  /// Gravity magnitude along -z, cells/s^2. Default 49050 (9.81 m/s^2 at 0.2 mm cells), range [0, 1e6].
  /// Applied with its hydrostatic pressure split off per column (docs/GRID.md), so resting paint
  /// feels no net force whatever the solver's accuracy; what is left is held by the yield stress.
  float gravity = 49050.f;
  /// The canvas's tilt from the horizontal, degrees: 0 flat on a table, 90 upright on an easel.
  /// Gravity splits into g cos(tilt) across the canvas (-z, its hydrostatic part split off per
  /// column) and g sin(tilt) in the canvas plane along +y, down the easel (the top view's rows
  /// grow downwards); the particles and the bristles feel the same vector (gravity_vector).
  /// Default 0, range [0, 90]. docs/GRID.md "The canvas on an easel".
  float tilt = 0.f;
  /// Wet paint at most this thick in a column (cells, above the dried paint or the canvas) that
  /// no bristle and no particle touches flows as a thin film: lubrication flow of the column's
  /// thickness under gravity, the Herschel-Bulkley paint's yield stress as a plug (docs/GRID.md
  /// "Thin films"). The grid's projection cannot level paint thinner than a cell: a groove in
  /// it has no pressure across it. Default 2 (0.4 mm), range [0, 4] (its explicit sub-steps grow as
  /// the cube: 7 a 1/60 s step at 2 cells, 56 at 4); 0 turns the film off.
  float film_max = 2.f;
  /// Surface tension of the paint's surface, N/m: it levels a thin film's grooves where its
  /// capillary stress passes the paint's yield stress (docs/GRID.md "Surface tension"). Default
  /// 0.033 (linseed oil and other vegetable oils, 0.031-0.035 N/m at 20-25 C; the binder forms
  /// the paint's surface), range [0, 0.1]; 0 turns it off.
  float surface_tension = 0.033f;
  /// Gravity in the canvas frame, cells/s^2: (0, g sin(tilt), -g cos(tilt)).
  Vec3 gravity_vector() const {
    const float a = tilt * (3.14159265f / 180.f);
    return Vec3(0.f, gravity * std::sin(a), -gravity * std::cos(a));
  }

  // --- cell classes ---
  /// Density (volume fraction) at and above which a cell is liquid in the projection.
  /// Default 0.5, range (0, 1]. Below it the cell is air (p = 0, free surface).
  float liquid_threshold = 0.5f;

  // --- drying (§4.2 "we also increase the dryness of every grid cell") ---
  /// Dryness added per second to every cell holding paint. Default 0.002 /s, range [0, 1000].
  float dry_rate = 0.002f;
  /// Dryness at and above which a cell holding paint is solid for brush, projection and
  /// advection. Default 0.95, range (0, 1].
  float dry_threshold = 0.95f;
  /// Paint whose every painted cell's faces carry less than this is at rest, cells/s: a replay
  /// passes over a pen-up pause from there in one call, drying only (Simulator::rest). Default
  /// 0.01 cells/s (2 µm/s: after a lift the flow falls below it within a second and settles
  /// near 1e-4, the creep of unyielded paint; docs/FORMATS.md "Pauses"), range [0, 100].
  float rest_speed = 0.01f;

  // --- advection and mass ---
  /// Measure ||div|| before and after each projection (GridStats::rhs_norm, residual_norm): two
  /// norms, two host reads a step. Default off.
  bool projection_norms = false;

  // --- active window (§4.2 last paragraph) ---
  /// Window origins snap to multiples of this many cells, so the window moves (a scatter and a
  /// gather) only when the brush has moved about this far. Default 8, range [1, 64].
  int window_snap = 8;
};

}  // namespace wb
