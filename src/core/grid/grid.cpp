// Grid stage dispatcher and step (paper §4.2, Algorithm 1): validates, then runs the
// backend drivers of grid_impl.h through WB_DISPATCH. The step reads like §4.2.
#include "core/grid/grid.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <utility>

#include "core/exec/algorithms.h"
#include "core/exec/dispatch.h"
#include "core/exec/memory.h"
#include "core/exec/profile.h"
#include "core/grid/project_kernels.h"

namespace wb {

namespace {
/// The paint's stiff (oil 0) and oily (oil 1) end members, which every oil interpolates
/// (rheology_at_oil): the viscosity's and the film's one source.
std::pair<HerschelBulkley, HerschelBulkley> paint_end_members(const GridParams& p) {
  return {HerschelBulkley{p.yield_stress_stiff, p.consistency_stiff, p.flow_index_stiff},
          HerschelBulkley{p.yield_stress_oily, p.consistency_oily, p.flow_index_oily}};
}

void check_params(const GridParams& p) {
  WB_REQUIRE(p.dt > 0.f && p.dt <= 0.1f, "grid: dt must be in (0, 0.1] s");
  WB_REQUIRE(p.jacobi_L >= 0 && p.jacobi_L <= 1000, "grid: jacobi_L must be in [0, 1000]");
  WB_REQUIRE(p.alpha >= 0.f && p.alpha <= 1.f, "grid: alpha must be in [0, 1]");
  WB_REQUIRE(p.solver_sweeps >= 0 && p.solver_sweeps <= 10000, "grid: solver_sweeps must be in [0, 10000]");
  WB_REQUIRE(p.jacobi_omega > 0.f && p.jacobi_omega <= 1.f, "grid: jacobi_omega must be in (0, 1]");
  WB_REQUIRE(p.chebyshev_rho >= 0.f && p.chebyshev_rho < 1.f, "grid: chebyshev_rho must be in [0, 1)");
  WB_REQUIRE(p.chebyshev_power_iterations >= 1 && p.chebyshev_power_iterations <= 1000,
             "grid: chebyshev_power_iterations must be in [1, 1000]");
  WB_REQUIRE(p.yield_stress_stiff >= 0.f && p.yield_stress_oily >= 0.f && p.yield_stress_stiff <= 1e4f &&
                 p.yield_stress_oily <= 1e4f,
             "grid: yield stresses must be in [0, 1e4] Pa");
  WB_REQUIRE(p.consistency_stiff > 0.f && p.consistency_oily > 0.f && p.consistency_stiff <= 1e5f &&
                 p.consistency_oily <= 1e5f,
             "grid: consistencies must be in (0, 1e5] Pa s^n");
  WB_REQUIRE(p.flow_index_stiff > 0.f && p.flow_index_oily > 0.f && p.flow_index_stiff <= 1.f &&
                 p.flow_index_oily <= 1.f,
             "grid: flow indices must be in (0, 1]");
  WB_REQUIRE(p.regularisation >= 1.f && p.regularisation <= 1e5f, "grid: regularisation must be in [1, 1e5] s");
  WB_REQUIRE(p.rho0 > 0.f && p.cell_size > 0.f, "grid: rho0 and cell_size must be positive");
  WB_REQUIRE(p.viscosity_tolerance >= 1e-7f && p.viscosity_tolerance <= 1.f,
             "grid: viscosity_tolerance must be in [1e-7, 1]");
  WB_REQUIRE(p.viscosity_max_iterations >= 0 && p.viscosity_max_iterations <= 10000,
             "grid: viscosity_max_iterations must be in [0, 10000]");
  WB_REQUIRE(p.gravity >= 0.f && p.gravity <= 1e6f, "grid: gravity must be in [0, 1e6] cells/s^2");
  WB_REQUIRE(p.tilt >= 0.f && p.tilt <= 90.f, "grid: the canvas tilt must be in [0, 90] degrees");
  WB_REQUIRE(p.film_max >= 0.f && p.film_max <= 4.f, "grid: film_max must be in [0, 4] cells");
  WB_REQUIRE(p.surface_tension >= 0.f && p.surface_tension <= 0.1f, "grid: surface_tension must be in [0, 0.1] N/m");
  WB_REQUIRE(p.liquid_threshold > 0.f && p.liquid_threshold <= 1.f, "grid: liquid_threshold must be in (0, 1]");
  WB_REQUIRE(p.dry_rate >= 0.f && p.dry_rate <= 1000.f, "grid: dry_rate must be in [0, 1000] /s");
  WB_REQUIRE(p.dry_threshold > 0.f && p.dry_threshold <= 1.f, "grid: dry_threshold must be in (0, 1]");
  WB_REQUIRE(p.window_snap >= 1 && p.window_snap <= 64, "grid: window_snap must be in [1, 64]");
}
}  // namespace

WB_DEFINE_DISPATCHERS(WB_GRID_KERNELS)

void SolverScratch::reserve(const Device& d, int64_t cells) {
  for (auto* b : {&y, &z, &r, &prev, &tmp}) {
    b->set_device(d);
    b->resize(size_t(cells));
  }
}

void poisson_apply(const Device& device, PoissonView s, const float* x, float* out) {
  poisson_apply_all(device, s, x, out);
}

double norm2(const Device& device, const float* v, int64_t n, SolverScratch& scratch, Workspace& ws) {
  scratch.tmp.resize(size_t(n));
  grid_square(device, v, scratch.tmp.data(), n);
  return std::sqrt(std::max(0.0, reduce_sum(device, scratch.tmp.data(), n, ws)));
}

void solve_pressure(const Device& device, PoissonView s, const float* b, float* x, const SolverConfig& cfg,
                    SolverScratch& sc, const std::function<void(int, const float*)>& observe) {
  const int64_t n = s.d.cells();
  WB_REQUIRE(cfg.sweeps >= 0, "solve_pressure: negative sweep count");
  sc.reserve(device, n);
  mem::fill_zero(device, x, size_t(n) * sizeof(float));
  switch (cfg.kind) {
    case PressureSolver::FixedPoint: {
      // Algorithm 1 in pressure space (Eq. 3): r = b - A x is minus the divergence of the
      // already-corrected velocity; two Jacobi sweeps from alpha * y give the next correction y.
      sc.y.fill_zero();
      const int L = cfg.sweeps / 2;
      for (int l = 0; l < L; ++l) {
        poisson_residual(device, s, b, x, sc.r.data());
        poisson_fixed_point_first(device, s, sc.r.data(), sc.y.data(), sc.z.data(), cfg.alpha);
        poisson_fixed_point_second(device, s, sc.r.data(), sc.z.data(), sc.y.data(), x);
        if (observe) observe(2 * (l + 1), x);
      }
      break;
    }
    case PressureSolver::Jacobi:
    case PressureSolver::WeightedJacobi: {
      const float omega = cfg.kind == PressureSolver::Jacobi ? 1.f : cfg.omega;
      float* cur = x;
      float* nxt = sc.y.data();
      for (int k = 0; k < cfg.sweeps; ++k) {
        poisson_jacobi(device, s, b, cur, nxt, omega);
        std::swap(cur, nxt);
        if (observe) observe(k + 1, cur);
      }
      if (cur != x) mem::copy_on_device(device, x, cur, size_t(n) * sizeof(float));
      break;
    }
    case PressureSolver::Chebyshev: {
      WB_REQUIRE(cfg.rho > 0.f && cfg.rho < 1.f, "solve_pressure: Chebyshev needs rho in (0, 1)");
      // x^{k+1} = omega_{k+1} (J x^k - x^{k-1}) + x^{k-1}  (Eq. 6 in iterate form).
      float* prev = sc.prev.data();
      float* cur = x;
      float* nxt = sc.y.data();
      sc.prev.fill_zero();
      float omega = 1.f;
      for (int k = 0; k < cfg.sweeps; ++k) {
        omega = chebyshev_omega(k, cfg.rho, omega);
        poisson_chebyshev(device, s, b, cur, prev, nxt, omega);
        float* old_prev = prev;
        prev = cur;
        cur = nxt;
        nxt = old_prev;
        if (observe) observe(k + 1, cur);
      }
      if (cur != x) mem::copy_on_device(device, x, cur, size_t(n) * sizeof(float));
      break;
    }
  }
}

float estimate_jacobi_rho(const Device& device, PoissonView s, int iters, SolverScratch& sc, Workspace& ws) {
  const int64_t n = s.d.cells();
  sc.reserve(device, n);
  grid_fill_hash(device, sc.y.data(), s.cls, n, 12345u);
  sc.r.fill_zero();  // b = 0: each sweep applies D^-1 R
  double nrm = norm2(device, sc.y.data(), n, sc, ws);
  if (nrm <= 0.0) return 0.f;
  float* cur = sc.y.data();
  float* nxt = sc.z.data();
  double ratio = 0.0;
  for (int k = 0; k < iters; ++k) {
    grid_scale(device, cur, float(1.0 / nrm), n);
    poisson_jacobi(device, s, sc.r.data(), cur, nxt, 1.f);
    std::swap(cur, nxt);
    nrm = norm2(device, cur, n, sc, ws);
    if (nrm <= 0.0) return 0.f;
    ratio = nrm;
  }
  return float(std::min(ratio, 0.9999));
}

Grid::Grid(TileStore& canvas, const GridParams& params, Int3 dims, Int3 origin)
    : params_(params), window_(canvas, dims, origin), ws_(canvas.device()) {
  check_params(params_);
  const Device& d = device();
  const GridDims g = window_.grid_dims();
  for (int c = 0; c < 3; ++c) {
    for (auto* b : {&theta_[c], &solid_vel_[c], &vel_pre_[c], &vel_tmp_[c]}) {
      b->set_device(d);
      b->resize(size_t(g.faces(c)));
      b->fill_zero();
    }
  }
  cls_.set_device(d);
  cls_.resize(size_t(g.cells()));
  cls_.fill_zero();
  for (int c = 0; c < 3; ++c) {
    fluid_[c].set_device(d);
    fluid_[c].resize(size_t(g.faces(c)));
    fluid_[c].fill_zero();
  }
  for (auto* b : {&pressure_, &rhs_, &cell_tmp_, &mu_}) {
    b->set_device(d);
    b->resize(size_t(g.cells()));
    b->fill_zero();
  }
  // Also six values a column (grid_column_tops), more than the cells of a window under 6 layers.
  cell_tmp_.resize(std::max(size_t(g.cells()), size_t(6) * size_t(g.nx) * size_t(g.ny)));
  const size_t all_faces = size_t(g.nu() + g.nv() + g.nw());
  face_tmp_.set_device(d);
  face_tmp_.resize(all_faces);
  for (auto& b : film_) {
    b.set_device(d);
    b.resize(size_t(kFilmFields) * size_t(g.nx) * size_t(g.ny));
  }
  {
    FilmSolve& fs = film_solve_;
    const size_t columns = size_t(g.nx) * size_t(g.ny);
    for (auto* b : {&fs.flag, &fs.idx, &fs.list, &fs.go, &fs.flowed, &fs.pairs_done, &fs.steps_go}) b->set_device(d);
    for (auto* b : {&fs.flowed, &fs.pairs_done, &fs.steps_go}) b->resize(1);
    for (auto* b : {&fs.cinv, &fs.diag, &fs.x, &fs.r, &fs.p, &fs.q, &fs.sums}) b->set_device(d);
    fs.count.set_device(d), fs.lap.set_device(d);
    for (auto* b : {&fs.flag, &fs.idx, &fs.list}) b->resize(2 * columns);
    for (auto* b : {&fs.cinv, &fs.diag, &fs.x, &fs.r, &fs.p, &fs.q}) b->resize(2 * columns);
    fs.lap.resize(columns);
    fs.sums.resize(6), fs.go.resize(1), fs.count.resize(1);
  }
  for (auto* b : {&visc_flag_, &visc_idx_, &visc_list_}) {
    b->set_device(d);
    b->resize(all_faces);
  }
  visc_flag_.fill_zero();  // then written over each step's extent: outside it no face is fluid
  cg_nb_.set_device(d);
  cg_nu_.set_device(d);
  for (auto* b : {&cg_x_, &cg_r_, &cg_p_, &cg_q_, &cg_diag_}) b->set_device(d);
  cg_sums_.set_device(d);
  cg_sums_.resize(6);
  cg_go_.set_device(d);
  cg_go_.resize(1);
  record_.set_device(d);
  record_.resize(1);
  cg_count_.set_device(d);
  cg_count_.resize(1);
  cg_partial_.set_device(d);
  cg_partial_.resize(kSumBlocks);
  cg_ticket_.set_device(d);
  cg_ticket_.resize(1);
  cg_ticket_.fill_zero();
  advect_max_.set_device(d);
  advect_max_.resize(kAdvectMaxSlots);
  advect_plan_.set_device(d);
  advect_plan_.resize(1);
  advect_plan_.fill_zero();
  const size_t tiles = size_t((g.nx + kPaintTile - 1) / kPaintTile) * size_t((g.ny + kPaintTile - 1) / kPaintTile);
  for (auto* b : {&tile_mark_, &tile_active_, &tile_halo_, &tile_painted_[0], &tile_painted_[1], &tile_process_}) {
    b->set_device(d);
    b->resize(tiles);
  }
  tile_counts_.set_device(d);
  tile_counts_.resize(5);
  pass_below_.set_device(d);
  pass_below_.resize(2);
  // Every cell until the first step has found the paint's (its stages then visit them all once).
  GridExtent all{};
  set_layers(all, g, g.nz);
  all.dirty = g.nz;
  all.dirty_box[1] = g.nx;
  all.dirty_box[3] = g.ny;
  extent_.set_device(d);
  extent_.copy_from_host(&all, 1);
  advect_extent_.set_device(d);
  advect_extent_.resize(2);
  paint_tmp_ = PaintWindow(d, dims);
  scratch_.reserve(d, g.cells());
  classify();
}

GridView Grid::view() {
  GridView v{};
  v.d = window_.grid_dims();
  for (int c = 0; c < 3; ++c) {
    v.vel[c] = window_.velocity(c).data();
    v.theta[c] = theta_[c].data();
    v.solid_vel[c] = solid_vel_[c].data();
    v.fluid[c] = fluid_[c].data();
  }
  v.cls = cls_.data();
  v.pressure = pressure_.data();
  v.extent = stage_extent_;
  return v;
}

bool Grid::move_window(Int3 new_origin) {
  WB_PROFILE_SCOPE("grid.move_window");
  const bool moved = !(new_origin == window_.origin());
  window_.move_to(new_origin);
  stats_.window_moved = moved;
  return moved;
}

void Grid::classify() {
  WB_PROFILE_SCOPE("grid.classify");
  grid_classify(device(), view(), window_.paint().view(), bristles_, particle_density_, window_.canvas().dims(), flow_,
                params_.liquid_threshold, params_.dry_threshold);
}

void Grid::advect(float dt) {
  WB_PROFILE_SCOPE("grid.advect");
  WB_REQUIRE(dt > 0.f && std::isfinite(dt), "Grid::advect: dt must be positive");
  const Device& d = device();
  const GridDims g = dims();
  PaintWindow& paint = window_.paint();
  paint_tmp_.set_origin(paint.origin());
  GridView v = view();
  // Paint: flux form on the faces of the last step's velocity, in passes along one axis each,
  // each face's flux the paint between it and its departure point (face_paint_carry): a pass
  // moves paint as far as the flow takes it at the cost of one, so the step's work does not grow
  // with the pen's speed. The axes alternate x y z and z y x from step to step (Strang).
  // The classes and face fractions the advection reads (solids, dried paint never moved) lie in
  // the cells of the paint and particles and a few beyond: those of the columns and layers
  // holding them first, found on the device, for the outflow rates; the rest once the plan
  // (below) has told how far the paint moves. Beyond, nothing in the step reads them
  // (docs/GRID.md).
  column_maxima(kTraceDensity, kPaintTop);
  grid_first_extent(d, g, advect_max_.data() + kJointTop, advect_extent_.data(), advect_max_.data() + kRateX);
  within(advect_extent_.data(), [&] {
    classify();
    grid_paint_outflow(d, view(), paint.density.data(), advect_max_.data() + kRateX);
  });
  // The largest outflow rate along each axis make, with the layers holding paint and those
  // holding paint or particles, the step's plan on the device: the paint's reach along each axis,
  // the layers and columns its passes visit, and the box the velocity's advection classifies.
  // The passes run over the device's counts, so the host reads none of it (docs/GRID.md "Work in
  // proportion to the paint").
  grid_advect_plan(d, g, advect_max_.data() + kRateX, advect_max_.data() + kPaintTop, advect_max_.data() + kJointTop,
                   dt, advect_plan_.data(), advect_extent_.data() + 1);
  within(advect_extent_.data() + 1, [&] {
    classify();
    advect_paint(dt);
  });
  // Velocity: backtrace every fluid face through a copy of the field, up to the layers that can
  // hold liquid in this step; an air face keeps its extrapolated velocity, and nothing in the step
  // reads one where there is no paint (docs/GRID.md "Advection and mass").
  for (int c = 0; c < 3; ++c)
    mem::copy_on_device(d, vel_tmp_[c].data(), v.vel[c], size_t(g.faces(c)) * sizeof(float));
  within(advect_extent_.data() + 1,
         [&] { grid_advect_velocity(d, view(), vel_tmp_[0].data(), vel_tmp_[1].data(), vel_tmp_[2].data(), dt); });
}

void Grid::advect_paint(float dt) {
  const Device& d = device();
  const GridDims g = dims();
  PaintWindow& paint = window_.paint();
  const GridView v = view();
  // Work in proportion to the paint: the plan's tiles within the paint's reach (and the layers
  // up to its reach up) compute fluxes; the scratch copy takes the ring of halo tiles and the
  // layers above, which the passes' walks read, from the paint once (docs/GRID.md "Work in
  // proportion to the paint").
  tile_counts_.fill_zero();
  grid_paint_tiles(d, g, paint.density.data(), paint.dryness.data(), params_.dry_threshold, advect_plan_.data(),
                   tile_mark_.data(), tile_active_.data(), tile_halo_.data(), tile_counts_.data(), pass_below_.data());
  const int tiles_x = (g.nx + kPaintTile - 1) / kPaintTile, tiles_y = (g.ny + kPaintTile - 1) / kPaintTile;
  const PaintTiles tiles{.active = tile_active_.data(),
                         .halo = tile_halo_.data(),
                         .counts = tile_counts_.data(),
                         .plan = advect_plan_.data(),
                         .tiles_x = tiles_x,
                         .capacity = int64_t(tiles_x) * tiles_y * kPaintTile * g.nz};
  grid_copy_paint_tiles(d, g, tiles, paint.view(), paint_tmp_.view(), TileCopy::kIntoScratch);
  // Which tiles held paint that can move after the last pass (before the first: the paint's) and
  // after this one; which the step's passes visit; the layers holding paint after each pass.
  int32_t* painted[2] = {tile_painted_[0].data(), tile_painted_[1].data()};
  int32_t* below[2] = {pass_below_.data(), pass_below_.data() + 1};
  const size_t tile_bytes = tile_mark_.size() * sizeof(int32_t);
  mem::copy_on_device(d, painted[0], tile_mark_.data(), tile_bytes);
  mem::fill_zero(d, tile_process_.data(), tile_bytes);
  // A pass along each axis. The host does not know along which the paint flows: a pass along an
  // axis without flow (the plan's reach 0) writes nothing and hands its flags on, and each pass
  // that moves paint reads the buffers the last one wrote (advect_in_scratch), on the device.
  for (int n = 0; n < 3; ++n) {
    const int axis = advect_order_ == 0 ? n : 2 - n;
    mem::fill_zero(d, painted[1], tile_bytes);
    mem::copy_on_device(d, below[1], below[0], sizeof(int32_t));
    grid_paint_tiles_pass(d, g, tiles, painted[0], axis, tile_process_.data(), painted[1]);
    grid_advect_paint_axis(d, v, paint.view(), paint_tmp_.view(), axis, n, advect_order_, dt, params_.dry_threshold,
                           tiles, tile_process_.data(), painted[1], below[0], below[1]);
    std::swap(painted[0], painted[1]);
    std::swap(below[0], below[1]);
  }
  advect_order_ = 1 - advect_order_;
  // An odd number of passes that moved paint left the result in the scratch buffers, complete
  // only where the passes wrote: the paint's own buffers are complete elsewhere, so they take
  // those tiles back (the copy does nothing after an even number).
  grid_copy_paint_tiles(d, g, tiles, paint_tmp_.view(), paint.view(), TileCopy::kResultBack);
}

void Grid::column_maxima(float trace, int slot) {
  const GridDims g = dims();
  const int64_t columns = int64_t(g.nx) * g.ny;
  const PaintWindow& paint = window_.paint();
  grid_column_tops(device(), g, paint.density.data(), paint.dryness.data(), params_.dry_threshold, particle_density_,
                   trace, cell_tmp_.data());
  for (int s = 0; s < 6; ++s)
    reduce_max_into(device(), cell_tmp_.data() + s * columns, columns, advect_max_.data() + slot + s, ws_);
}

void Grid::running_box_into(float* out, float speed) {
  const GridDims g = dims();
  const int64_t columns = int64_t(g.nx) * g.ny;
  grid_running_columns(device(), view(), window_.paint().view(), params_.dry_threshold, speed, cell_tmp_.data());
  for (int s = 0; s < 4; ++s) reduce_max_into(device(), cell_tmp_.data() + s * columns, columns, out + s, ws_);
}

void Grid::find_extent() {
  column_maxima(0.f, kExtentPaintTop);
  grid_extent(device(), dims(), advect_max_.data() + kJointTop, advect_max_.data() + kExtentTop, extent_.data());
}

void Grid::rheology() {
  WB_PROFILE_SCOPE("grid.rheology");
  const auto [stiff, oily] = paint_end_members(params_);
  const PaintWindow& paint = window_.paint();
  const JointOil oil{paint.density.data(), paint.oil.data(), particle_density_, particle_oil_};
  grid_effective_viscosity(device(), view(), oil, stiff, oily, params_.regularisation, mu_.data());
}

void Grid::add_external_forces(float dt) {
  WB_PROFILE_SCOPE("grid.forces");
  // Eq. 11's old grid velocity: after advection and the particles' momentum, before the forces,
  // the viscous step and the projection (particles in the paint get their weight from the grid).
  const GridDims g = dims();
  GridView v = view();
  for (int c = 0; c < 3; ++c)
    mem::copy_on_device(device(), vel_pre_[c].data(), v.vel[c], size_t(g.faces(c)) * sizeof(float));
  if (params_.gravity <= 0.f) return;
  const Vec3 gv = params_.gravity_vector();
  grid_gravity(device(), view(), cell_tmp_.data(), -gv.z * dt, gv.y * dt);
}

void Grid::apply_viscosity(float dt) {
  WB_PROFILE_SCOPE("grid.viscosity");
  const Device& d = device();
  GridView v = view();
  cg_sums_.fill_zero();  // the record's figures are this step's, zero where nothing is solved
  // The flags every step (visc_flag_ is kept over the extents), the solve where it runs.
  grid_viscous_flags(d, v, visc_flag_.data());
  if (params_.viscosity_max_iterations <= 0) return;
  // The fluid faces, compacted: the solve costs in proportion to the paint, not to the window.
  // Their count stays on the device (ListCount), and the vectors hold every face of the window,
  // so that no count has to come back before the solve (docs/GRID.md "Viscosity").
  const int64_t all = int64_t(visc_idx_.size());
  exclusive_scan_into(d, visc_flag_.data(), visc_idx_.data(), all, ws_);
  grid_viscous_list(d, v, visc_idx_.data(), visc_list_.data());
  // (1 - dt div(nu grad)) u = u_old, nu = mu / rho0 in cells^2/s.
  const double h = params_.cell_size;
  const float nu_scale = float(double(dt) / (double(params_.rho0) * h * h));
  const uint32_t* list = visc_list_.data();
  const uint32_t* idx = visc_idx_.data();
  if (cg_x_.size() != size_t(all)) {
    cg_nb_.resize(6 * size_t(all));
    cg_nu_.resize(size_t(all));
    for (auto* b : {&cg_x_, &cg_r_, &cg_p_, &cg_q_, &cg_diag_}) b->resize(size_t(all));
  }
  // Jacobi-preconditioned conjugate gradients (Saad 2003, Alg. 9.1) from the velocity before the
  // forces: gravity's uniform dt g is the smoothest error there is (the mode the no-slip floor
  // holds, the slowest for Jacobi-CG), and resting paint keeps almost none of it.
  // alpha, beta and the test of convergence are formed on the device from sums kept there
  // (cg_sums_: r.z of the current and the next iteration, p.Ap, b.D^-1 b, the iterations made,
  // the fluid faces), and the device runs the iterations until the test or the iteration limit
  // stops them (LaunchLoop): the host waits for none of it. The sums come back with the step's
  // record (record_into).
  const double tol2 = double(params_.viscosity_tolerance) * double(params_.viscosity_tolerance);
  const int max_it = params_.viscosity_max_iterations;
  double* sums = cg_sums_.data();
  const SumScratch sum{cg_partial_.data(), cg_ticket_.data()};
  const ListCount n{cg_count_.data(), all};
  grid_viscous_count(d, v, idx, cg_count_.data(), sums + 5);
  grid_viscous_setup(d, v, list, n, idx, mu_.data(), nu_scale, cg_nu_.data(), cg_nb_.data(), cg_diag_.data(),
                     cg_r_.data(), cg_x_.data(), FaceFields{{vel_pre_[0].data(), vel_pre_[1].data(), vel_pre_[2].data()}});
  // The right-hand side b goes into r; A x into q (its p.Ap lands in slot 2, which the first
  // iteration writes again), then b.D^-1 b, r = b - A x, p = D^-1 r and r.z.
  grid_viscous_apply(d, n, cg_nu_.data(), cg_nb_.data(), cg_diag_.data(), cg_x_.data(), cg_q_.data(), sums + 2, {},
                     sum);
  const uint64_t key = launch_key({launch_key_of(cg_x_.data()), launch_key_of(cg_nb_.data()),
                                   launch_key_of(cg_nu_.data()), launch_key_of(sums), uint64_t(all), uint64_t(max_it),
                                   std::bit_cast<uint64_t>(tol2)});
  run_pcg(cg_loop_, key, n, PcgVectors{cg_x_.data(), cg_r_.data(), cg_p_.data(), cg_q_.data(), cg_diag_.data(), sums,
                                       cg_go_.data()},
          tol2, max_it, [&](const CgGuard& guard) {
            grid_viscous_apply(d, n, cg_nu_.data(), cg_nb_.data(), cg_diag_.data(), cg_p_.data(), cg_q_.data(),
                               sums + 2, guard, sum);
          });
  grid_viscous_write(d, v, list, n, cg_x_.data());
}

template <class Apply>
void Grid::run_pcg(LaunchLoop& loop, uint64_t key, ListCount n, PcgVectors v, double tol2, int max_it, Apply apply) {
  const Device& d = device();
  const SumScratch sum{cg_partial_.data(), cg_ticket_.data()};
  double* sums = v.sums;
  grid_pcg_start(d, n, v.r, v.q, v.diag, v.p, sums + 0, sums + 3, sum);
  // An iteration: p.Ap (apply, into slot 2), the update (r.z into slot 1), the direction, and the
  // test, which moves r.z to slot 0 and sets the loop's flag. Every pass also tests (CgGuard), so
  // that a solve that starts converged moves nothing in its one pass.
  const CgGuard guard{sums + 0, sums + 3, tol2};
  loop.run(d, key, v.go, [&] {
    apply(guard);
    grid_pcg_update(d, n, guard, sums + 2, v.p, v.q, v.diag, v.x, v.r, sums + 1, sums + 4, sum);
    grid_pcg_direction(d, n, guard, sums + 1, v.r, v.diag, v.p);
    grid_pcg_continue(d, sums + 0, sums + 1, sums + 3, tol2, sums + 4, max_it, v.go);
  });
}

void Grid::record_into(GridRecord* out) const {
  mem::copy_on_device(device(), &out->advect, advect_plan_.data(), sizeof(AdvectPlan));
  mem::copy_on_device(device(), out->viscosity, cg_sums_.data(), sizeof(out->viscosity));
}

void Grid::take_record(const GridRecord& r) {
  stats_.advect_passes = r.advect.passes;
  stats_.advect_courant = r.advect.courant;
  // The sums of the last solve (apply_viscosity): r.z in slot 0, b.D^-1 b in 3, the iterations
  // in 4, the fluid faces in 5; all zero where no solve ran.
  stats_.viscosity_faces = int(r.viscosity[5]);
  stats_.viscosity_iterations = int(r.viscosity[4]);
  stats_.viscosity_residual =
      r.viscosity[3] > 0.0 ? std::sqrt(std::max(r.viscosity[0], 0.0) / r.viscosity[3]) : 0.0;
}

void Grid::read_record() {
  record_into(record_.data());
  GridRecord r{};
  record_.copy_to_host(&r, 1);
  take_record(r);
}

void Grid::compute_rhs(float dt) {
  grid_rhs(device(), view(), dt > 0.f ? window_.paint().density.data() : nullptr, dt > 0.f ? 1.f / dt : 0.f,
           rhs_.data());
}

void Grid::project(float dt) {
  WB_PROFILE_SCOPE("grid.project");
  const Device& d = device();
  const GridDims g = dims();
  GridView v = view();
  compute_rhs(dt);
  SolverConfig cfg;
  cfg.kind = params_.solver;
  cfg.alpha = params_.alpha;
  cfg.omega = params_.jacobi_omega;
  cfg.sweeps = params_.solver == PressureSolver::FixedPoint ? 2 * params_.jacobi_L : params_.solver_sweeps;
  if (params_.solver == PressureSolver::Chebyshev) {
    cfg.rho = params_.chebyshev_rho > 0.f
                  ? params_.chebyshev_rho
                  : estimate_jacobi_rho(d, v.poisson(), params_.chebyshev_power_iterations, scratch_, ws_);
    if (!(cfg.rho > 0.f)) cfg.kind = PressureSolver::Jacobi;  // no liquid: plain sweeps on nothing
    stats_.chebyshev_rho = cfg.rho;
  }
  solve_pressure(d, v.poisson(), rhs_.data(), pressure_.data(), cfg, scratch_);
  if (params_.projection_norms) {
    stats_.rhs_norm = norm2(d, rhs_.data(), g.cells(), scratch_, ws_);
    poisson_residual(d, v.poisson(), rhs_.data(), pressure_.data(), scratch_.r.data());
    stats_.residual_norm = norm2(d, scratch_.r.data(), g.cells(), scratch_, ws_);
  }
  grid_apply_pressure(d, v, pressure_.data());
  grid_extrapolate(d, v);
}

void Grid::dry(float dt) {
  WB_PROFILE_SCOPE("grid.dry");
  if (params_.dry_rate <= 0.f) return;
  // §4.2 dries every cell: the window's cells here, the rest of the canvas by its clock.
  grid_dry(device(), window_.paint().view(), params_.dry_rate * dt);
  window_.canvas().advance_drying(double(params_.dry_rate) * double(dt));
}

void Grid::flow_film(float dt) {
  WB_PROFILE_SCOPE("grid.film");
  if (params_.film_max <= 0.f || params_.gravity <= 0.f) return;
  const GridDims g = dims();
  // Explicit sub-steps: the film's diffusivity rho0 g h^3 / (3 K) is largest for the thickest film
  // of the runniest paint; dt <= cell^2 / (4 D) keeps the explicit step stable. Known here, no wait.
  const float cell = params_.cell_size, rho0 = params_.rho0;
  const float g_si = params_.gravity * cell;  // cells/s^2 -> m/s^2
  const float h = params_.film_max * cell;
  const auto [stiff, oily] = paint_end_members(params_);
  const float D = rho0 * g_si * h * h * h / (3.f * std::min(oily.K, stiff.K));
  // In pairs, so that each pair ends in the plane it began in (the device's loop, below).
  const int pairs = std::max(1, int(std::ceil(dt * 2.f * D / (cell * cell))));
  const Vec3 gv = params_.gravity_vector();
  const FilmFlow f{stiff, oily, rho0 * -gv.z * cell, rho0 * gv.y * cell, cell, dt / float(2 * pairs),
                   params_.surface_tension};
  // The columns are read from the cells once, flow in their own planes, and are written back once.
  grid_film_columns(device(), g, extent_.data(), window_.paint().view(), bristles_, particle_density_, flow_,
                    params_.dry_threshold, params_.film_max, f, film_[0].data());
  // What the film lies on is the same in both planes: the sub-steps do not copy it.
  const size_t columns = size_t(g.nx) * size_t(g.ny);
  static_assert(kFilmAbove == kFilmBase + 1, "the base and the first layer over it are adjacent planes");
  mem::copy_on_device(device(), film_[1].data() + kFilmBase * columns, film_[0].data() + kFilmBase * columns,
                      2 * columns * sizeof(float));
  // The sub-steps' pairs run until one moves nothing (the film then stays as it is: stiff paint,
  // or runny paint come to rest) or all are made; the device decides, the host does not wait.
  FilmSolve& fs = film_solve_;
  fs.flowed.fill_zero();
  fs.pairs_done.fill_zero();
  const uint64_t key = launch_key(
      {launch_key_of(film_[0].data()), launch_key_of(film_[1].data()), launch_key_of(fs.flowed.data()),
       uint64_t(pairs), uint64_t(columns), launch_key_of(f.stiff.tau_y), launch_key_of(f.stiff.K),
       launch_key_of(f.stiff.n), launch_key_of(f.oily.tau_y), launch_key_of(f.oily.K), launch_key_of(f.oily.n),
       launch_key_of(f.rho_g_cos), launch_key_of(f.rho_g_sin), launch_key_of(f.cell), launch_key_of(f.dt)});
  fs.steps.run(device(), key, fs.steps_go.data(), [&] {
    grid_film_update(device(), g, film_[0].data(), f, film_[1].data(), fs.flowed.data());
    grid_film_update(device(), g, film_[1].data(), f, film_[0].data(), fs.flowed.data());
    grid_film_continue(device(), fs.flowed.data(), fs.pairs_done.data(), pairs, fs.steps_go.data());
  });
  // The pairs end in the first plane; surface tension's step moves it into the second.
  const bool capillary = params_.surface_tension > 0.f;
  if (capillary) film_capillarity(dt, f);
  grid_film_write(device(), g, window_.paint().view(), film_[capillary ? 1 : 0].data());
}

void Grid::film_capillarity(float dt, const FilmFlow& f) {
  const Device& d = device();
  const GridDims g = dims();
  FilmSolve& s = film_solve_;
  const float* col = film_[0].data();
  const int64_t faces = 2 * int64_t(g.nx) * g.ny;
  // The flowing faces, compacted as the viscous solve's: their count stays on the device.
  grid_film_curvature(d, g, col, s.lap.data());
  grid_film_capillary_flags(d, g, col, s.lap.data(), f, dt, s.flag.data());
  exclusive_scan_into(d, s.flag.data(), s.idx.data(), faces, ws_);
  grid_film_capillary_list(d, faces, s.flag.data(), s.idx.data(), s.list.data(), s.count.data());
  const ListCount n{s.count.data(), faces};
  grid_film_capillary_setup(d, g, col, s.lap.data(), s.list.data(), n, f, dt, s.cinv.data(), s.diag.data(),
                            s.r.data(), s.x.data(), s.q.data());
  // The viscous solve's Jacobi CG, tolerance and iteration bound.
  const double tol2 = double(params_.viscosity_tolerance) * double(params_.viscosity_tolerance);
  const int max_it = std::max(1, params_.viscosity_max_iterations);
  const SumScratch sum{cg_partial_.data(), cg_ticket_.data()};
  s.sums.fill_zero();
  const uint64_t key = launch_key({launch_key_of(col), launch_key_of(s.x.data()), launch_key_of(s.sums.data()),
                                   uint64_t(faces), uint64_t(max_it), std::bit_cast<uint64_t>(tol2)});
  run_pcg(s.loop, key, n, PcgVectors{s.x.data(), s.r.data(), s.p.data(), s.q.data(), s.diag.data(), s.sums.data(),
                                     s.go.data()},
          tol2, max_it, [&](const CgGuard& guard) {
            grid_film_capillary_apply(d, g, col, s.list.data(), n, s.flag.data(), s.idx.data(), s.cinv.data(),
                                      s.p.data(), s.q.data(), s.sums.data() + 2, guard, sum);
          });
  grid_film_capillary_move(d, g, col, s.flag.data(), s.idx.data(), s.x.data(), f, film_[1].data());
}

void Grid::step(float dt, const std::function<void()>& after_advection) {
  WB_PROFILE_SCOPE("grid.step");
  WB_REQUIRE(dt > 0.f && dt <= 0.1f, "Grid::step: dt must be in (0, 0.1] s");
  check_params(params_);
  advect(dt);
  if (after_advection) after_advection();  // the simulator joins the particles' fields here
  // From here on the stages visit only the layers that can hold liquid (docs/GRID.md "Work in
  // proportion to the paint"): above them no face is fluid and nothing moves.
  find_extent();
  within(extent_.data(), [&] {
    classify();  // liquid where the paint now is
    rheology();
    add_external_forces(dt);
    apply_viscosity(dt);
    project(dt);
  });
  flow_film(dt);
  dry(dt);  // the window's paint, whatever the extent
}

double Grid::divergence_norm(float dt) {
  compute_rhs(dt);
  return norm2(device(), rhs_.data(), dims().cells(), scratch_, ws_);
}

float Grid::max_fluid_speed() {
  grid_max_abs_fluid_velocity(device(), view(), face_tmp_.data());
  const GridDims g = dims();
  return reduce_max(device(), face_tmp_.data(), g.nu() + g.nv() + g.nw(), ws_);
}

}  // namespace wb
