// Grid-based liquid simulation (paper §4.2, Algorithm 1, Eq. 3-7; DESIGN steps 3 and 6).
// Grid owns the active window (paint fields + MAC velocity, re-centred on the brush) and
// runs the step as separate stages: move_window, advect, add_external_forces,
// apply_viscosity, project, dry. Units: positions in window cells, velocity in cells/s,
// dt in s. All buffers are sized once; no stage allocates.
#pragma once
#include <cstdint>
#include <functional>

#include "core/canvas/tile_store.h"
#include "core/exec/dispatch.h"
#include "core/exec/graph.h"
#include "core/grid/active_window.h"
#include "core/grid/grid_fields.h"
#include "core/grid/grid_params.h"
#include "core/grid/rheology.h"

namespace wb {

/// One step's counts and solver figures (the mass books are the simulator's, PaintBooks).
struct GridStats {
  int advect_passes = 0;        ///< one-axis passes of the paint's advection: one per axis along which it flows
  float advect_courant = 0;     ///< largest one-axis outflow Courant number of the paint (cells a step)
  double rhs_norm = 0;          ///< with projection_norms: ||rhs||_2 over liquid cells before the projection
  double residual_norm = 0;     ///< with projection_norms: ||residual||_2 after it
  float chebyshev_rho = 0;      ///< rho used by the Chebyshev solver (estimated or given)
  int viscosity_faces = 0;      ///< fluid faces of the last viscous solve
  int viscosity_iterations = 0; ///< CG iterations it took
  double viscosity_residual = 0;///< relative residual it reached (sqrt(r D^-1 r / b D^-1 b))
  bool window_moved = false;
};

/// Which solver and how many sweeps, for solve_pressure().
struct SolverConfig {
  PressureSolver kind = PressureSolver::FixedPoint;
  int sweeps = 6;       ///< Jacobi-type sweeps; the fixed-point method runs sweeps/2 iterations (L)
  float alpha = 1.f;    ///< Algorithm 1
  float omega = 0.8f;   ///< weighted Jacobi
  float rho = 0.f;      ///< Chebyshev spectral-radius estimate (must be in (0,1) for Chebyshev)
};

/// Scratch of the solvers (sized to the cell count once).
struct SolverScratch {
  DeviceBuffer<float> y, z, r, prev, tmp;
  void reserve(const Device& d, int64_t cells);
};

/// Solves A x = b approximately by cfg (x starts at 0). observe(sweeps_done, x) runs after each
/// iteration when given (the solver study); it must not write x.
void solve_pressure(const Device& device, PoissonView s, const float* b, float* x, const SolverConfig& cfg,
                    SolverScratch& scratch, const std::function<void(int, const float*)>& observe = {});
/// Spectral radius of D^-1 R on the liquid cells by power iteration (iters sweeps, b = 0).
float estimate_jacobi_rho(const Device& device, PoissonView s, int iters, SolverScratch& scratch, Workspace& ws);
/// ||v||_2 of a cell array, in double.
double norm2(const Device& device, const float* v, int64_t n, SolverScratch& scratch, Workspace& ws);
/// out = A x.
void poisson_apply(const Device& device, PoissonView s, const float* x, float* out);

class Grid {
 public:
  /// Gathers the window at `origin` (canvas cells; z is normally 0) from `canvas`.
  Grid(TileStore& canvas, const GridParams& params = {}, Int3 dims = {128, 128, 32}, Int3 origin = {0, 0, 0});

  GridParams& params() { return params_; }
  const GridParams& params() const { return params_; }
  ActiveWindow& window() { return window_; }
  const ActiveWindow& window() const { return window_; }
  const Device& device() const { return window_.device(); }
  GridDims dims() const { return window_.grid_dims(); }
  GridView view();
  PoissonView poisson() { return view().poisson(); }

  /// Rasterised bristles for this step (cell-centred on the window; nullable = no brush).
  /// The pointers must stay valid until the next call.
  void set_bristles(const BristleField& b) { bristles_ = b; }
  /// Rasterised particle volume (cell-centred volume fraction, device; nullable) that joins the
  /// grid density when cells are classified (the joint density of §4.3), and the particles' oil
  /// in the same units (sum of volume times oil fraction; nullable: the grid's oil alone), which
  /// joins the grid's in the rheology. Valid until the next call.
  void set_particle_density(const float* density, const float* oil = nullptr) {
    particle_density_ = density;
    particle_oil_ = density ? oil : nullptr;
  }
  /// The columns where paint flows from now on (canvas cells; FlowColumns): outside them the
  /// window's cells are walls. The simulator keeps them a fixed distance from the brush.
  void set_flow_columns(const FlowColumns& f) { flow_ = f; }
  /// The box of the columns whose wet paint runs faster than `speed` (cells/s) on a face of its
  /// cells across the canvas (u, v), as the maxima of x, -x, y and -y (canvas cells; -inf where
  /// none), into out[0..4) on the device: where paint runs, for the window of a resting brush.
  void running_box_into(float* out, float speed);
  /// This step's particle density on the window (cell fractions), or null before the joint fields.
  const float* particle_density() const { return particle_density_; }

  // --- stages (call in this order; step() does) ---
  /// Window to `new_origin` (scatter, shift velocity, gather). Returns whether it moved.
  bool move_window(Int3 new_origin);
  /// Cell classes and open face fractions from paint, dryness and bristles.
  void classify();
  /// Advection of the paint fields (flux form) and the velocity (semi-Lagrangian, RK2 backtrace),
  /// after classifying the layers it reads: those of the paint and particles and a few above.
  void advect(float dt);
  /// Apparent viscosity of each liquid cell (rheology.h) at the strain rate of the flow, before
  /// this step's forces: a force the paint resists below its yield stress must not yield it. One
  /// evaluation per step: the yield surface follows the flow with a lag of one step.
  void rheology();
  /// Keeps the velocity (Eq. 11's old grid velocity), then gravity on faces touching liquid,
  /// hydrostatic part split off (docs/GRID.md).
  void add_external_forces(float dt);
  /// Implicit viscosity with the apparent viscosity of each liquid cell at its strain rate, solved
  /// by PCG to viscosity_tolerance, from the velocity add_external_forces found (the guess only:
  /// the answer is the same within the tolerance whatever it is).
  void apply_viscosity(float dt);
  /// Projects with params().solver: the velocity loses its divergence, except where paint is
  /// packed above density 1, which it expands back over dt (compression_source).
  void project(float dt);
  /// Dryness += dry_rate * dt in every cell holding paint: the window's, and the canvas's by
  /// its drying clock (TileStore::advance_drying).
  void dry(float dt);
  /// advect (with its classification), after_advection (the simulator joins the particles'
  /// density and momentum to the grid there, §4.3), classify, rheology, add_external_forces,
  /// apply_viscosity, project, dry. The one step driver of the grid stage.
  void step(float dt, const std::function<void()>& after_advection = {});

  // --- for the particles (FLIP/PIC, Eq. 11) ---
  /// MAC velocity before the forces, the viscous and the pressure steps (component c = 0,1,2):
  /// the grid velocity Eq. 11's FLIP difference is taken against.
  const DeviceBuffer<float>& velocity_before_solve(int c) const { return vel_pre_[c]; }
  /// Apparent viscosity of each liquid cell at the last viscous step, Pa s (0 elsewhere).
  const DeviceBuffer<float>& apparent_viscosity() const { return mu_; }
  const DeviceBuffer<float>& pressure() const { return pressure_; }
  /// Right-hand side of the last projection (liquid cells): -div plus the compression source.
  const DeviceBuffer<float>& rhs() const { return rhs_; }

  // --- diagnostics ---
  /// The last step's figures. Those the device makes (the advection's plan, the viscous solve's
  /// faces, iterations and residual) are the host's once they come back, with the simulator's
  /// step record (record_into, take_record) or, for a grid stepped alone, read_record.
  const GridStats& stats() const { return stats_; }
  /// Queues copies of the last step's device figures into `out` (device memory: a slot of the
  /// simulator's step record, read with it).
  void record_into(GridRecord* out) const;
  /// Takes the figures that came back with a step's record into stats().
  void take_record(const GridRecord& r);
  /// Reads the last step's device figures into stats() (a host wait: for a grid stepped alone).
  void read_record();
  /// The layers the last step's stages after the joint fields visited (device; docs/GRID.md).
  const DeviceBuffer<GridExtent>& extent() const { return extent_; }
  /// ||div||_2 of the current velocity over liquid cells, against the compression source of
  /// packed paint when dt > 0 (as the projection of that step measures it).
  double divergence_norm(float dt = 0.f);
  /// Largest |velocity| on faces touching liquid, cells/s.
  float max_fluid_speed();
  /// Recomputes the right-hand side b = -div u into rhs() (used by project and the study), plus
  /// the compression source of packed paint when dt > 0.
  void compute_rhs(float dt = 0.f);
  Workspace& workspace() { return ws_; }
  SolverScratch& solver_scratch() { return scratch_; }

 private:
  GridParams params_;
  ActiveWindow window_;
  BristleField bristles_{};
  FlowColumns flow_{};
  const float* particle_density_ = nullptr;
  const float* particle_oil_ = nullptr;
  DeviceBuffer<float> theta_[3], solid_vel_[3], vel_pre_[3], vel_tmp_[3];
  DeviceBuffer<uint8_t> cls_, fluid_[3];
  DeviceBuffer<float> pressure_, rhs_, cell_tmp_, face_tmp_, mu_;
  // Viscous solve: fluid faces as a compact list (idx maps a global face to its entry), and
  // the conjugate-gradient vectors over the list. Sized to every face of the window once.
  // Per entry: nu dt, the six neighbour entries, and the CG vectors (68 bytes: the solve's
  // vectors hold every face, so that no count comes back before it; z = D^-1 r is not kept, and
  // b is formed in r).
  // visc_flag_: 1 at a fluid face, written over each step's extent only (faces outside it are
  // no longer fluid since the step that last visited them, as for the fluid flags themselves).
  DeviceBuffer<uint32_t> visc_flag_, visc_idx_, visc_list_;
  DeviceBuffer<int32_t> cg_nb_;
  DeviceBuffer<float> cg_nu_;
  /// The viscous CG's x, r, p, q = A p and the matrix's diagonal, in double (viscous_apply says why).
  DeviceBuffer<double> cg_x_, cg_r_, cg_p_, cg_q_, cg_diag_;
  /// The CG's scalars on the device: r.z of the current and the next iteration, p.Ap, b.D^-1 b,
  /// the iterations made, the fluid faces counted (they come back with the step's record).
  DeviceBuffer<double> cg_sums_;
  DeviceBuffer<uint32_t> cg_go_;  ///< the CG loop's flag: 1, another iteration (LaunchLoop)
  /// The fluid faces the solve's kernels run over (ListCount::n).
  DeviceBuffer<int64_t> cg_count_;
  /// The scratch of the iterations' dot products (parallel_sum_count): a partial a block, a ticket.
  DeviceBuffer<double> cg_partial_;
  DeviceBuffer<uint32_t> cg_ticket_;
  LaunchLoop cg_loop_;  ///< the CG's iterations, run by the device until converged
  /// A Jacobi CG's vectors and its device scalars (cg_sums_'s layout) and loop flag.
  struct PcgVectors {
    double *x, *r, *p, *q, *diag, *sums;
    uint32_t* go;
  };
  /// Jacobi-preconditioned CG (Saad 2003, Alg. 9.1) over the n entries of v from x, with b in r
  /// and A x in q on entry, run by `loop` (keyed by `key`) until the test or max_it stops it;
  /// apply(guard) writes q = A p and p.Ap into sums[2]. The viscous and the film's solves.
  template <class Apply>
  void run_pcg(LaunchLoop& loop, uint64_t key, ListCount n, PcgVectors v, double tol2, int max_it, Apply apply);
  DeviceBuffer<GridRecord> record_;  ///< read_record's copy of the step's device figures
  /// The advection's maxima: the outflow rate along each axis (slots 0-2), then column_maxima's
  /// six (the top layers holding paint and paint or particles, the latter's box), which make the
  /// step's AdvectPlan on the device; then column_maxima's six again after the particles joined
  /// (find_extent). None is read by the host.
  enum AdvectMax { kRateX = 0, kPaintTop = 3, kJointTop = 4, kExtentPaintTop = 9, kExtentTop = 10, kAdvectMaxSlots = 15 };
  DeviceBuffer<float> advect_max_;
  DeviceBuffer<AdvectPlan> advect_plan_;                       ///< the step's plan (grid_advect_plan)
  DeviceBuffer<int32_t> tile_mark_, tile_active_, tile_halo_;  ///< the advection's tiles (PaintTiles)
  /// Per tile: whether it held paint that can move after the last pass and after this one
  /// (swapped each pass), and whether a pass of the step visits it.
  DeviceBuffer<int32_t> tile_painted_[2], tile_process_;
  DeviceBuffer<int32_t> pass_below_;  ///< the layers holding paint after the last pass and this one (swapped)
  int advect_order_ = 0;  ///< the axes' order of the next step's passes: x y z, then z y x (Strang)
  DeviceBuffer<int64_t> tile_counts_;
  DeviceBuffer<GridExtent> extent_;  ///< the layers the stages after the joint fields visit (device)
  /// The advection's classifications: the layers holding paint or particles, then those the
  /// step's advection reads (advect()).
  DeviceBuffer<GridExtent> advect_extent_;
  const GridExtent* stage_extent_ = nullptr;  ///< the extent the stages visit now; null: the whole window
  /// Runs fn with the stages bounded by e (null: the whole window), the bound undone however fn ends.
  template <class F>
  void within(const GridExtent* e, F fn) {
    struct Bound {
      const GridExtent*& at;
      const GridExtent* was;
      ~Bound() { at = was; }
    } bound{stage_extent_, stage_extent_};
    stage_extent_ = e;
    fn();
  }
  /// The layers holding paint or particles now, or liquid before the advection: extent_.
  void find_extent();
  /// Thin films (GridParams::film_max): their lubrication flow over dt, in explicit sub-steps
  /// (pairs of them, run by the device until a pair moves nothing), then surface tension's step.
  void flow_film(float dt);
  /// The maxima of grid_column_tops (wet paint and particles above `trace`) into advect_max_'s six
  /// slots from `slot`: the paint's top, the joint top, then x, -x, y, -y of the joint columns.
  void column_maxima(float trace, int slot);
  /// The paint's passes of advect(), one along each axis, by the step's plan (advect_plan_).
  void advect_paint(float dt);
  PaintWindow paint_tmp_;
  DeviceBuffer<float> film_[2];  ///< flow_film's columns (FilmField planes), this sub-step's and the next
  /// The film's surface tension solve (flow_film), over its 2 nx ny faces (the x faces, then the
  /// y faces): each face's flag (it flows) and index, the flowing faces' list and count, L0 s of
  /// the columns, and the CG's 1 / c, diagonal, vectors and sums (the viscous solve's layout).
  struct FilmSolve {
    /// The gravity sub-steps' loop: paint crossed a face in this pair, the pairs made, another pair.
    DeviceBuffer<uint32_t> flowed, pairs_done, steps_go;
    LaunchLoop steps;
    DeviceBuffer<uint32_t> flag, idx, list, go;
    DeviceBuffer<int64_t> count;
    DeviceBuffer<float> lap;
    DeviceBuffer<double> cinv, diag, x, r, p, q, sums;
    LaunchLoop loop;
  } film_solve_;
  /// Surface tension's step of the film in film_[0] into film_[1] (flow_film).
  void film_capillarity(float dt, const FilmFlow& f);
  SolverScratch scratch_;
  Workspace ws_;
  GridStats stats_;
};

// The grid stage's backend drivers (grid_impl.h), one list (core/exec/dispatch.h).
#define WB_GRID_KERNELS(X)                                                                                             \
  X(void, grid_classify,                                                                                               \
    (GridView g, PaintWindowView pw, BristleField br, const float* particle_density, CanvasDims canvas,                \
     FlowColumns flow, float liquid_threshold, float dry_threshold),                                                   \
    (g, pw, br, particle_density, canvas, flow, liquid_threshold, dry_threshold))                                      \
  X(void, grid_column_tops,                                                                                            \
    (GridDims d, const float* rho, const float* dryness, float dry_threshold, const float* particle_density,           \
     float trace, float* out),                                                                                         \
    (d, rho, dryness, dry_threshold, particle_density, trace, out))                                                    \
  X(void, grid_first_extent, (GridDims d, const float* maxima, GridExtent* e, float* rates), (d, maxima, e, rates))    \
  X(void, grid_running_columns, (GridView g, PaintWindowView pw, float dry_threshold, float speed, float* out),        \
    (g, pw, dry_threshold, speed, out))                                                                                \
  X(void, grid_advect_plan,                                                                                            \
    (GridDims d, const float* rates, const float* paint_top, const float* joint, float dt, AdvectPlan* plan,           \
     GridExtent* e),                                                                                                   \
    (d, rates, paint_top, joint, dt, plan, e))                                                                         \
  X(void, grid_paint_outflow, (GridView g, const float* rho, float* rates), (g, rho, rates))                           \
  X(void, grid_advect_paint_axis,                                                                                      \
    (GridView g, PaintWindowView paint, PaintWindowView scratch, int axis, int pass, int order, float dt,              \
     float dry_threshold, PaintTiles tiles, const int32_t* process, int32_t* painted, const int32_t* below,            \
     int32_t* below_next),                                                                                             \
    (g, paint, scratch, axis, pass, order, dt, dry_threshold, tiles, process, painted, below, below_next))             \
  X(void, grid_paint_tiles_pass,                                                                                       \
    (GridDims d, PaintTiles tiles, const int32_t* before, int axis, int32_t* process, int32_t* after),                 \
    (d, tiles, before, axis, process, after))                                                                          \
  X(void, grid_paint_tiles,                                                                                            \
    (GridDims d, const float* rho, const float* dryness, float dry_threshold, const AdvectPlan* plan, int32_t* mark,   \
     int32_t* active, int32_t* halo, int64_t* counts, int32_t* below),                                                 \
    (d, rho, dryness, dry_threshold, plan, mark, active, halo, counts, below))                                         \
  X(void, grid_copy_paint_tiles,                                                                                       \
    (GridDims d, PaintTiles tiles, PaintWindowView src, PaintWindowView dst, TileCopy what),                           \
    (d, tiles, src, dst, what))                                                                                        \
  X(void, grid_advect_velocity, (GridView g, const float* u, const float* v, const float* w, float dt),                \
    (g, u, v, w, dt))                                                                                                  \
  X(void, grid_film_columns,                                                                                           \
    (GridDims d, const GridExtent* e, PaintWindowView pw, BristleField br, const float* particle_density,              \
     FlowColumns flow, float dry_threshold, float film_max, FilmFlow f, float* col),                                   \
    (d, e, pw, br, particle_density, flow, dry_threshold, film_max, f, col))                                           \
  X(void, grid_film_update, (GridDims d, const float* col, FilmFlow f, float* next, uint32_t* flowed),                 \
    (d, col, f, next, flowed))                                                                                         \
  X(void, grid_film_continue, (uint32_t * flowed, uint32_t* pairs_done, int pairs, uint32_t* go),                      \
    (flowed, pairs_done, pairs, go))                                                                                   \
  X(void, grid_film_write, (GridDims d, PaintWindowView pw, const float* col), (d, pw, col))                           \
  X(void, grid_film_curvature, (GridDims d, const float* col, float* lap), (d, col, lap))                              \
  X(void, grid_film_capillary_flags,                                                                                   \
    (GridDims d, const float* col, const float* lap, FilmFlow f, float dt, uint32_t* flag),                           \
    (d, col, lap, f, dt, flag))                                                                                        \
  X(void, grid_film_capillary_list,                                                                                    \
    (int64_t faces, const uint32_t* flag, const uint32_t* idx, uint32_t* list, int64_t* count),                       \
    (faces, flag, idx, list, count))                                                                                   \
  X(void, grid_film_capillary_setup,                                                                                   \
    (GridDims d, const float* col, const float* lap, const uint32_t* list, ListCount cnt, FilmFlow f, float dt,       \
     double* cinv, double* diag, double* r, double* x, double* q),                                                     \
    (d, col, lap, list, cnt, f, dt, cinv, diag, r, x, q))                                                              \
  X(void, grid_film_capillary_apply,                                                                                   \
    (GridDims d, const float* col, const uint32_t* list, ListCount cnt, const uint32_t* flag, const uint32_t* idx,   \
     const double* cinv, const double* p, double* q, double* pq, CgGuard guard, SumScratch s),                         \
    (d, col, list, cnt, flag, idx, cinv, p, q, pq, guard, s))                                                          \
  X(void, grid_film_capillary_move,                                                                                    \
    (GridDims d, const float* col, const uint32_t* flag, const uint32_t* idx, const double* x, FilmFlow f,            \
     float* next),                                                                                                     \
    (d, col, flag, idx, x, f, next))                                                                                   \
  X(void, grid_gravity, (GridView g, float* ph, float g_dt, float g_dt_y), (g, ph, g_dt, g_dt_y))                      \
  X(void, grid_effective_viscosity,                                                                                    \
    (GridView g, JointOil oil, HerschelBulkley stiff, HerschelBulkley oily, float m, float* mu),                       \
    (g, oil, stiff, oily, m, mu))                                                                                      \
  X(void, grid_viscous_flags, (GridView g, uint32_t * flag), (g, flag))                                                \
  X(void, grid_viscous_list, (GridView g, const uint32_t* idx, uint32_t* list), (g, idx, list))                        \
  X(void, grid_viscous_count, (GridView g, const uint32_t* idx, int64_t* run, double* total), (g, idx, run, total))    \
  X(void, grid_viscous_setup,                                                                                          \
    (GridView g, const uint32_t* list, ListCount n, const uint32_t* idx, const float* mu, float nu_scale, float* nu,   \
     int32_t* nb, double* diag, double* b, double* x, FaceFields guess),                                               \
    (g, list, n, idx, mu, nu_scale, nu, nb, diag, b, x, guess))                                                        \
  X(void, grid_viscous_apply,                                                                                          \
    (ListCount n, const float* nu, const int32_t* nb, const double* diag, const double* p, double* q, double* pq,      \
     CgGuard guard, SumScratch s),                                                                                     \
    (n, nu, nb, diag, p, q, pq, guard, s))                                                                             \
  X(void, grid_pcg_start,                                                                                              \
    (ListCount n, double* r, const double* ax, const double* diag, double* p, double* rz, double* bz, SumScratch s),   \
    (n, r, ax, diag, p, rz, bz, s))                                                                                    \
  X(void, grid_pcg_update,                                                                                             \
    (ListCount n, CgGuard guard, const double* pq, const double* p, const double* q, const double* diag, double* x,    \
     double* r, double* rz, double* iterations, SumScratch s),                                                         \
    (n, guard, pq, p, q, diag, x, r, rz, iterations, s))                                                               \
  X(void, grid_pcg_direction,                                                                                          \
    (ListCount n, CgGuard guard, const double* rz_new, const double* r, const double* diag, double* p),                \
    (n, guard, rz_new, r, diag, p))                                                                                    \
  X(void, grid_pcg_continue,                                                                                           \
    (double* rz, const double* rz_new, const double* bnorm, double tol2, const double* iterations, int max_it,         \
     uint32_t* go),                                                                                                    \
    (rz, rz_new, bnorm, tol2, iterations, max_it, go))                                                                 \
  X(void, grid_viscous_write, (GridView g, const uint32_t* list, ListCount n, const double* x), (g, list, n, x))       \
  X(void, grid_rhs, (GridView g, const float* rho, float inv_dt, float* b), (g, rho, inv_dt, b))                       \
  X(void, poisson_jacobi, (PoissonView s, const float* b, const float* x, float* out, float omega),                    \
    (s, b, x, out, omega))                                                                                             \
  X(void, poisson_residual, (PoissonView s, const float* b, const float* x, float* r), (s, b, x, r))                   \
  X(void, poisson_chebyshev,                                                                                           \
    (PoissonView s, const float* b, const float* x, const float* x_prev, float* out, float omega_k),                   \
    (s, b, x, x_prev, out, omega_k))                                                                                   \
  X(void, poisson_fixed_point_first, (PoissonView s, const float* r, const float* y, float* out, float alpha),         \
    (s, r, y, out, alpha))                                                                                             \
  X(void, poisson_fixed_point_second, (PoissonView s, const float* r, const float* z, float* y_out, float* x),         \
    (s, r, z, y_out, x))                                                                                               \
  X(void, poisson_apply_all, (PoissonView s, const float* x, float* out), (s, x, out))                                 \
  X(void, grid_apply_pressure, (GridView g, const float* p), (g, p))                                                   \
  X(void, grid_extrapolate, (GridView g), (g))                                                                         \
  X(void, grid_extent, (GridDims d, const float* before, const float* after, GridExtent* e), (d, before, after, e))    \
  X(void, grid_dry, (PaintWindowView pw, float amount), (pw, amount))                                                  \
  X(void, grid_shift_edges, (float* dst, int ex, int ey, int ez, int dx, int dy), (dst, ex, ey, ez, dx, dy))           \
  X(void, grid_max_abs_fluid_velocity, (GridView g, float* out), (g, out))                                             \
  X(void, grid_square, (const float* x, float* out, int64_t n), (x, out, n))                                           \
  X(void, grid_scale, (float* x, float s, int64_t n), (x, s, n))                                                       \
  X(void, grid_fill_hash, (float* x, const uint8_t* cls, int64_t n, uint32_t seed), (x, cls, n, seed))
WB_DECLARE_KERNELS(WB_GRID_KERNELS)

}  // namespace wb
