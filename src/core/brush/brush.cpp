// The brush stage's host side (paper §4.1): owns the device buffers, computes the
// brush frame's motion from consecutive poses (Eq. 2), validates, and dispatches the
// stage drivers of brush_impl.h in the order of one step.
#include "core/brush/brush.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/brush/brush_kernels.h"
#include "core/brush/brush_stages.h"
#include "core/brush/samples_kernels.h"
#include "core/exec/algorithms.h"
#include "core/exec/memory.h"
#include "core/exec/profile.h"

namespace wb {

WB_DEFINE_DISPATCHERS(WB_BRUSH_KERNELS)

namespace {

bool finite_pose(const BrushPose& p) {
  bool ok = isfinite3(p.position);
  for (const auto& r : p.rotation.r) ok = ok && isfinite3(r);
  return ok;
}

/// max |R^T R - I|: a pose's rotation must be orthonormal (a shear would distort the brush).
float orthonormality_error(const Mat3& R) {
  const Mat3 m = transpose(R) * R;
  float e = 0.f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e = std::max(e, std::fabs(m.r[i][j] - (i == j ? 1.f : 0.f)));
  return e;
}

void check_pose(const BrushPose& p, const char* where) {
  WB_REQUIRE(finite_pose(p), std::string(where) + ": brush pose is not finite");
  const float e = orthonormality_error(p.rotation);
  WB_REQUIRE(e < 1e-3f, std::string(where) + ": brush pose rotation is not orthonormal (|R^T R - I| = " +
                            std::to_string(e) + ")");
  WB_REQUIRE(std::fabs(p.position.x) < 1e8f && std::fabs(p.position.y) < 1e8f && std::fabs(p.position.z) < 1e8f,
             std::string(where) + ": brush pose position out of range");
}

int bit_width(uint64_t v) {
  int b = 0;
  while (v) {
    ++b;
    v >>= 1;
  }
  return b;
}
}  // namespace

Brush::Brush(const Device& device, const BrushSpec& spec, const BrushPose& pose, const BrushSolverParams& params)
    : device_(device), spec_(spec), params_(params), layout_(build_bristle_layout(spec)), ws_(device) {
  WB_REQUIRE(params.iterations >= 1 && params.iterations <= 100, "brush solver: iterations must be in 1..100");
  WB_REQUIRE(params.density_iterations >= 0 && params.density_iterations <= 20,
             "brush solver: density_iterations must be in 0..20");
  WB_REQUIRE(params.damping >= 0.f && params.damping <= 1000.f, "brush solver: damping must be in [0, 1000] 1/s");
  check_pose(pose, "Brush");
  device_.activate();

  const int64_t N = vertex_count(), S = sample_count();
  const int V = spec.vertices_per_bristle, B = spec.bristles;
  for (auto* b : {&xb_, &vb_, &x_, &v_, &xb_old_, &vb_old_, &x_old_, &v_old_, &delta_, &root_, &dir_, &prev_x_,
                  &prev_t_, &prev_n_, &prev_v_, &prev_omega_})
    b->set_device(device);
  for (auto* b : {&xb_, &vb_, &x_, &v_, &xb_old_, &vb_old_, &x_old_, &v_old_, &delta_}) b->resize(size_t(N));
#define WB_X(type, name, doc)   \
  s_##name##_.set_device(device); \
  s_##name##_.resize(size_t(S));  \
  s_##name##_.fill_zero();
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  for (auto* b : {&prev_x_, &prev_t_, &prev_n_, &prev_v_, &prev_omega_}) {
    b->resize(size_t(S));
    b->fill_zero();
  }

  // Rest description.
  std::vector<float> seg(size_t(N), 0.f);
  std::vector<float> bend(static_cast<size_t>(B));
  const float it_ratio = float(brush::kReferenceIterations) / float(params.iterations);
  for (int k = 0; k < B; ++k) {
    for (int i = 1; i < V; ++i) seg[size_t(k) * V + i] = layout_.length[size_t(k)] / float(V - 1);
    // Müller et al. 2007 §3.3: k' = 1 - (1 - k)^(n_ref / n) keeps the per-step effect of the
    // stiffness independent of the iteration count.
    bend[size_t(k)] = 1.f - std::pow(1.f - layout_.stiffness[size_t(k)], it_ratio);
  }
  seg_length_.set_device(device);
  seg_length_.copy_from_host(seg);
  bend_k_.set_device(device);
  bend_k_.copy_from_host(bend);
  root_.copy_from_host(layout_.root);
  dir_.copy_from_host(layout_.dir);

  // Minimum-density constraint: s_min = 2 r (bristles touching), never more than 0.9 of the
  // closest rest spacing, so that the rest shape satisfies the constraint.
  s_min_ = params.min_spacing > 0.f ? params.min_spacing : 2.f * spec.bristle_radius;
  s_min_ = std::min(s_min_, 0.9f * layout_.min_rest_spacing);
  uint32_t table = 1024;
  while (table < uint32_t(2 * N)) table <<= 1;
  grid_mask_ = table - 1;
  grid_bits_ = bit_width(grid_mask_);
  for (auto* b : {&grid_keys_, &grid_ids_, &cell_start_, &cell_end_, &contact_keys_, &contact_vals_}) b->set_device(device);
  grid_keys_.resize(size_t(N));
  grid_ids_.resize(size_t(N));
  cell_start_.resize(table);
  cell_end_.resize(table);
  lambda_.set_device(device);
  lambda_.resize(size_t(N));
  contact_keys_.resize(size_t(S));
  contact_vals_.resize(size_t(S));
  for (int k = 0; k < 2; ++k) {
    scan_w_[k].set_device(device);
    scan_w_[k].resize(size_t(S));
    scan_v_[k].set_device(device);
    scan_v_[k].resize(size_t(S));
  }
  scratch_a_.set_device(device);
  scratch_b_.set_device(device);
  scratch_a_.resize(size_t(std::max(N, S)));
  scratch_b_.resize(size_t(std::max(N, S)));
  nonfinite_.set_device(device);
  nonfinite_.resize(3);
  nonfinite_.fill_zero();
  count_.set_device(device);
  count_.resize(1);
  // Reserve the sort's scratch now so that the first step does not allocate.
  ws_.get(size_t(std::max(N, S)) * 2 * sizeof(uint32_t) + 4096);

  reset(pose);
}

BristleState Brush::state_view() {
  return BristleState{xb_.data(),     vb_.data(),    x_.data(),     v_.data(),       xb_old_.data(),
                      vb_old_.data(), x_old_.data(), v_old_.data(), delta_.data(), spec_.bristles,
                      spec_.vertices_per_bristle};
}

BristleRest Brush::rest_view() const {
  return BristleRest{root_.data(), dir_.data(), seg_length_.data(), bend_k_.data()};
}

SamplePrev Brush::prev_view() {
  return SamplePrev{prev_x_.data(), prev_t_.data(), prev_n_.data(), prev_v_.data(), prev_omega_.data()};
}

SampleView Brush::samples() {
  SampleView v{};
#define WB_X(type, name, doc) v.name = s_##name##_.data();
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  v.bristles = spec_.bristles;
  v.per_bristle = spec_.samples_per_bristle;
  return v;
}

BrushFrame Brush::frame_for(const BrushPose& pose) const {
  BrushFrame f{};
  f.R = pose.rotation;
  f.R_B = pose.R_B();
  f.p = pose.position;
  return f;
}

void Brush::reset(const BrushPose& pose) {
  check_pose(pose, "Brush::reset");
  pose_ = pose;
  frame_v_ = Vec3();
  frame_omega_B_ = Vec3();
  xb_.copy_from_host(layout_.rest);
  const BrushFrame f = frame_for(pose);
  brush_place(device_, state_view(), rest_view(), f);
  sample_history_ = 0;
  update_samples(1.f, f, SolidField{});  // at rest: the canvas plane only
}

void Brush::step(const BrushPose* poses, int substeps, float dt, const BrushEnvironment& env) {
  WB_PROFILE_SCOPE("brush.step");
  WB_REQUIRE(poses && substeps >= 1, "Brush::step: needs at least one sub-step pose");
  WB_REQUIRE(std::isfinite(dt) && dt > 0.f && dt <= 1.f, "Brush::step: dt must be in (0, 1] s (got " + std::to_string(dt) + ")");
  for (int k = 0; k < substeps; ++k) check_pose(poses[k], "Brush::step");
  WB_REQUIRE(env.friction >= 0.f && env.friction <= 1.f, "Brush::step: friction must be in [0, 1]");
  WB_REQUIRE(isfinite3(env.gravity), "Brush::step: gravity is not finite");
  if (env.drag) {
    const DragField& d = *env.drag;
    WB_REQUIRE(d.u && d.v && d.w && d.density && d.nx > 0 && d.ny > 0 && d.nz > 0,
               "Brush::step: drag field needs u, v, w, density and positive dimensions");
    WB_REQUIRE(std::isfinite(d.k) && d.k >= 0.f, "Brush::step: drag coefficient must be finite and >= 0");
  }
  if (env.solid.valid)
    WB_REQUIRE(env.solid.tiles.slot_of_tile && env.solid.tiles.density && env.solid.tiles.dryness,
               "Brush::step: solid field is marked valid but has no tile store");

  const float dt_sub = dt / float(substeps);
  BrushFrame f{};
  for (int k = 0; k < substeps; ++k) f = substep(poses[k], dt_sub, env);
  // The samples once per step, with the motion made over the whole step.
  WB_PROFILE_SCOPE("brush.samples");
  update_samples(dt, f, env.solid);
}

BrushFrame Brush::substep(const BrushPose& pose, float dt, const BrushEnvironment& env) {
  // Motion of the brush frame (Eq. 2): linear and angular velocity from consecutive poses,
  // their rates from the previous step's.
  BrushFrame f = frame_for(pose);
  const Vec3 v_now = (pose.position - pose_.position) / dt;
  const Vec3 omega_canvas = brush::rotation_vector(pose.rotation * transpose(pose_.rotation)) / dt;
  const Vec3 omega_B = f.R_B * omega_canvas;
  f.vdot_B = f.R_B * ((v_now - frame_v_) / dt);
  f.omega_B = omega_B;
  f.omegadot_B = (omega_B - frame_omega_B_) / dt;

  BrushForces forces{};
  forces.gravity = env.gravity;
  forces.has_drag = env.drag != nullptr;
  if (env.drag) forces.drag = *env.drag;
  const float friction_it = 1.f - std::pow(1.f - env.friction, 1.f / float(params_.iterations));

  const BristleState s = state_view();
  const BristleRest r = rest_view();
  {
    WB_PROFILE_SCOPE("brush.integrate");
    brush_integrate(device_, s, r, f, forces, spec_.beta_B, 1.f - std::exp(-params_.damping * dt), dt);
  }
  {
    WB_PROFILE_SCOPE("brush.constraints");
    brush_solve(device_, s, r, f, env.solid, params_.iterations, friction_it);
    brush_inextensible(device_, s, r, f, env.solid);
  }
  {
    // Last but for a length-exact pass, so that bristles pressed together keep apart: its
    // corrections are lateral and carried down each bristle, which that pass leaves intact.
    WB_PROFILE_SCOPE("brush.min_density");
    apply_min_density(params_.density_iterations);
    brush_inextensible(device_, s, r, f, env.solid);
  }
  brush_velocities(device_, s, f, env.solid, dt);
  // Containment: a non-finite vertex never propagates; the sub-step is undone, on the device
  // (the host learns of it from rollback_counter(), read with the step's record).
  const int64_t N = vertex_count();
  FloatArrays state;
  state.add(reinterpret_cast<const float*>(xb_.data()), 3 * N);
  state.add(reinterpret_cast<const float*>(vb_.data()), 3 * N);
  count_nonfinite_each_into(device_, state, nonfinite_.data(), ws_);
  brush_restore(device_, s, f, nonfinite_.data());
  frame_v_ = v_now;
  frame_omega_B_ = omega_B;
  pose_ = pose;
  return f;
}

void Brush::apply_min_density(int iterations) {
  if (iterations <= 0 || spec_.bristles < 2 || !(s_min_ > 0.f)) return;
  const BristleState s = state_view();
  const int64_t N = vertex_count();
  MinDensityGrid g{};
  g.ids = grid_ids_.data();
  g.cell_start = cell_start_.data();
  g.cell_end = cell_end_.data();
  g.mask = grid_mask_;
  g.h = 2.f * s_min_;
  g.rho0 = brush::density_kernel(s_min_, g.h);
  const float grad = 2.f / s_min_;  // |grad C| of one neighbour at s_min
  g.eps = 1e-3f * grad * grad;
  // The same launches every sub-step (about ten an iteration, the sort's among them): on CUDA
  // one graph's replay.
  const uint64_t key = launch_key({launch_key_of(xb_.data()), launch_key_of(grid_keys_.data()),
                                   launch_key_of(cell_start_.data()), launch_key_of(lambda_.data()),
                                   launch_key_of(ws_.data()), uint64_t(ws_.bytes()), uint64_t(N),
                                   uint64_t(iterations), launch_key_of(g.h)});
  density_graph_.run(device_, key, [&] {
    for (int it = 0; it < iterations; ++it) {
      brush_grid_keys(device_, s, g.h, grid_mask_, grid_keys_.data(), grid_ids_.data());
      sort_by_key(device_, grid_keys_.data(), grid_ids_.data(), N, grid_bits_, ws_);
      cell_start_.fill_zero();  // start == end: an empty bucket
      cell_end_.fill_zero();
      brush_grid_ranges(device_, grid_keys_.data(), N, cell_start_.data(), cell_end_.data());
      brush_density_lambda(device_, s, g, lambda_.data());
      brush_density_delta(device_, s, g, lambda_.data());
      brush_density_apply(device_, s);
    }
  });
}

void Brush::update_samples(float dt, const BrushFrame& frame, const SolidField& solid) {
  const SampleView sv = samples();
  const SamplePrev prev = prev_view();
  samples_spline(device_, state_view(), sv, prev, solid);
  samples_frames(device_, sv, frame,
                 FrameScan{{scan_w_[0].data(), scan_w_[1].data()}, {scan_v_[0].data(), scan_v_[1].data()}});
  samples_motion(device_, sv, prev, dt, sample_history_);
  sample_history_ = std::min(sample_history_ + 1, 2);
}

void Brush::rasterize(Int3 window_origin, Int3 window_dims, float* psi, float* vx, float* vy, float* vz,
                      TouchListBuffers* cells) {
  WB_PROFILE_SCOPE("brush.rasterize");
  WB_REQUIRE(window_dims.x > 0 && window_dims.y > 0 && window_dims.z > 0, "Brush::rasterize: window dims must be positive");
  WB_REQUIRE(psi && vx && vy && vz, "Brush::rasterize: null output pointer");
  const int64_t n = int64_t(window_dims.x) * window_dims.y * window_dims.z;
  WB_REQUIRE(!cells || cells->capacity() == n, "Brush::rasterize: the cell list is not the window's");
  if (cells) {
    // The fields hold the last raster at the cells it listed and 0 elsewhere: those go back to 0,
    // so that the raster costs in proportion to the bristles, not to the window.
    samples_raster_clear(device_, n, psi, vx, vy, vz, cells->view());
    cells->clear_count();
  } else {
    for (float* p : {psi, vx, vy, vz}) mem::fill_zero(device_, p, size_t(n) * sizeof(float));
  }
  const TouchList list = cells ? cells->view() : TouchList{};
  samples_rasterize(device_, samples(), spec_.bristle_radius, window_origin, window_dims, psi, vx, vy, vz, list);
  samples_rasterize_finish(device_, n, psi, vx, vy, vz, list);
}

int64_t Brush::mark_contacts(int32_t* trace, int trace_w, int trace_h, int ox, int oy, float contact_height,
                             const SolidField& solid) {
  mark_contacts_into(trace, trace_w, trace_h, ox, oy, contact_height, solid, count_.data());
  double n = 0;
  count_.copy_to_host(&n, 1);
  return int64_t(std::llround(n));
}

void Brush::mark_contacts_into(int32_t* trace, int trace_w, int trace_h, int ox, int oy, float contact_height,
                               const SolidField& solid, double* count) {
  WB_PROFILE_SCOPE("brush.contacts");
  WB_REQUIRE(trace && trace_w > 0 && trace_h > 0, "Brush::mark_contacts: empty trace");
  WB_REQUIRE(uint64_t(trace_w) * uint64_t(trace_h) < (uint64_t(1) << 31), "Brush::mark_contacts: trace too large");
  WB_REQUIRE(std::isfinite(contact_height) && contact_height >= 0.f, "Brush::mark_contacts: bad contact height");
  const int64_t S = sample_count();
  const uint32_t sentinel = uint32_t(trace_w) * uint32_t(trace_h);
  samples_contact_keys(device_, samples(), solid, contact_height, trace, trace_w, trace_h, ox, oy, contact_keys_.data(),
                       contact_vals_.data());
  sort_by_key(device_, contact_keys_.data(), contact_vals_.data(), S, bit_width(sentinel), ws_);
  count_distinct_flags(device_, contact_keys_.data(), S, sentinel, scratch_a_.data());
  reduce_sum_into(device_, scratch_a_.data(), S, count, ws_);
}

void Brush::max_stretch_into(float* out) {
  brush_stretch_and_z(device_, state_view(), rest_view(), scratch_a_.data(), scratch_b_.data());
  reduce_max_into(device_, scratch_a_.data(), vertex_count(), out, ws_);
}

void Brush::rolled_back(int64_t total) {
  if (total <= rollbacks_) return;
  // The motion of the undone sub-steps is forgotten: the frame's rates and the samples' history
  // start again from the state that was kept.
  rollbacks_ = total;
  frame_v_ = Vec3();
  frame_omega_B_ = Vec3();
  sample_history_ = 0;
}

BrushStats Brush::stats() {
  BrushStats st;
  const int64_t N = vertex_count(), S = sample_count();
  brush_stretch_and_z(device_, state_view(), rest_view(), scratch_a_.data(), scratch_b_.data());
  st.max_stretch = reduce_max(device_, scratch_a_.data(), N, ws_);
  const float zv = reduce_min(device_, scratch_b_.data(), N, ws_);
  samples_z(device_, samples(), scratch_b_.data());
  st.min_z = std::min(zv, reduce_min(device_, scratch_b_.data(), S, ws_));
  int64_t total = 0;
  nonfinite_.copy_range_to_host(&total, 2, 1);
  rolled_back(total);
  st.nonfinite = rollbacks_;
  return st;
}

std::vector<Vec3> Brush::vertices_to_host() const { return x_.to_host(); }
std::vector<Vec3> Brush::vertices_brush_frame_to_host() const { return xb_.to_host(); }
std::vector<Vec3> Brush::vertex_velocities_to_host() const { return v_.to_host(); }
std::vector<Vec3> Brush::samples_to_host() const { return s_x_.to_host(); }
std::vector<std::vector<Vec3>> Brush::sample_fields_to_host() const {
  std::vector<std::vector<Vec3>> out;
#define WB_X(type, name, doc) out.push_back(s_##name##_.to_host());
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  return out;
}

}  // namespace wb
