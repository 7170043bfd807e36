// Liquid transfer stage (paper §5, Eq. 12-16): validation, scratch, the order of the passes
// and the books of each transfer. Dispatches every pass to wb::cpu or wb::cuda.
#include "core/transfer/transfer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/exec/algorithms.h"
#include "core/exec/dispatch.h"
#include "core/exec/error.h"
#include "core/exec/profile.h"
#include "core/particles/particles.h"
#include "core/transfer/bristle_particle_kernels.h"

namespace wb {

TransferParams TransferParams::for_bristle_radius(float r) const {
  TransferParams p = *this;
  const float s = std::pow(r / kCapacityRadius, 3.f);
  p.M_max *= s;
  p.M_min *= s;
  return p;
}

float TransferParams::absorb_range() const {
  // M'_j = max((1 - mu psi) M_max, M_min) (Eq. 12) is at most max(M_max, M_min).
  return load_radius(std::max(M_max, M_min), cell_mass());
}
WB_DEFINE_DISPATCHERS(WB_TRANSFER_KERNELS)

namespace {

void validate(const TransferParams& p) {
  auto in = [](float v, float lo, float hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  WB_REQUIRE(in(p.rho0, 1.f, 1e5f), "TransferParams: rho0 must lie in [1, 1e5] kg/m^3");
  WB_REQUIRE(in(p.cell_size, 1e-6f, 1.f), "TransferParams: cell_size must lie in [1e-6, 1] m");
  WB_REQUIRE(in(p.mu, 0.f, 1.f), "TransferParams: mu must lie in [0, 1] (Eq. 12)");
  // The parameter is at most 1e-5 kg for a 0.25-cell bristle; a brush of thicker bristles scales
  // it by the radius cubed (for_bristle_radius), up to 8000x for the thickest (5 cells).
  WB_REQUIRE(in(p.M_max, 1e-20f, 1e-1f), "TransferParams: M_max must lie in (0, 0.1] kg (Eq. 12)");
  WB_REQUIRE(in(p.M_min, 0.f, p.M_max), "TransferParams: M_min must lie in [0, M_max] (Eq. 12)");
  WB_REQUIRE(in(p.epsilon, 0.f, 10.f), "TransferParams: epsilon must lie in [0, 10]");
  WB_REQUIRE(in(p.surface_density, 1e-6f, 1.f), "TransferParams: surface_density must lie in (0, 1]");
  WB_REQUIRE(in(p.march_step, 0.05f, 1.f), "TransferParams: march_step must lie in [0.05, 1] cells");
  WB_REQUIRE(in(p.return_margin, 0.f, 100.f), "TransferParams: return_margin must lie in [0, 100] cells");
  WB_REQUIRE(in(p.wick_rate, 0.f, 1e6f), "TransferParams: wick_rate must lie in [0, 1e6] 1/s");
  WB_REQUIRE(in(p.wick_slide, 0.f, 1e5f), "TransferParams: wick_slide must lie in [0, 1e5] per cell slid");
  WB_REQUIRE(p.absorb_limit >= 0 && p.absorb_limit <= 1024, "TransferParams: absorb_limit must lie in [0, 1024]");
  WB_REQUIRE(p.emit_limit >= 0 && p.emit_limit <= 64, "TransferParams: emit_limit must lie in [0, 64]");
  WB_REQUIRE(in(p.emit_mass, 1e-20f, p.M_max), "TransferParams: emit_mass must lie in (0, M_max] kg");
  WB_REQUIRE(p.emit_pattern >= 1 && p.emit_pattern <= 64, "TransferParams: emit_pattern must lie in [1, 64]");
  WB_REQUIRE(in(p.bleed, 0.f, 1.f), "TransferParams: bleed must lie in [0, 1]");
  WB_REQUIRE(in(p.split, 0.f, 1.f), "TransferParams: split must lie in [0, 1]");
  WB_REQUIRE(in(p.kernel_h, 0.5f, 2.f), "TransferParams: kernel_h must lie in [0.5, 2] cells");
  WB_REQUIRE(in(p.slow_speed, 0.f, 1e4f), "TransferParams: slow_speed must lie in [0, 1e4] cells/s");
  WB_REQUIRE(in(p.min_cell_density, 0.f, 1.f), "TransferParams: min_cell_density must lie in [0, 1]");
  WB_REQUIRE(p.candidate_split >= 1 && p.candidate_split <= 3, "TransferParams: candidate_split must lie in [1, 3]");
  WB_REQUIRE(p.distance_block >= 1 && p.distance_block <= 16, "TransferParams: distance_block must lie in [1, 16]");
}

void validate(const TransferEnv& env) {
  const PaintWindowView& pw = env.paint;
  WB_REQUIRE(pw.density && pw.pigment_r && pw.pigment_y && pw.pigment_b && pw.oil && pw.dryness,
             "Transfer: the window's paint fields are missing");
  WB_REQUIRE(pw.nx > 0 && pw.ny > 0 && pw.nz > 0, "Transfer: empty window");
  WB_REQUIRE(std::isfinite(env.floor_z) && std::isfinite(env.D0) && env.D0 >= 0.f,
             "Transfer: floor_z and D0 must be finite, D0 >= 0");
  WB_REQUIRE(std::isfinite(env.dry_threshold) && env.dry_threshold > 0.f && env.dry_threshold <= 1.f,
             "Transfer: dry_threshold must lie in (0, 1]");
  if (env.velocity.u != nullptr)
    WB_REQUIRE(env.velocity.v && env.velocity.w && env.velocity.nx == pw.nx && env.velocity.ny == pw.ny &&
                   env.velocity.nz == pw.nz && env.velocity.ox == pw.ox && env.velocity.oy == pw.oy &&
                   env.velocity.oz == pw.oz,
               "Transfer: the velocity field must cover the paint window");
}

double rel_gap(double a, double b) {
  const double s = std::max(std::fabs(a), std::fabs(b));
  return s > 0 ? std::fabs(a - b) / s : 0.0;
}

}  // namespace

double TransferRecord::max_closure_error() const {
  return std::max({rel_gap(absorbed_from_particles, absorbed_into_bristles),
                   rel_gap(emitted_from_bristles, emitted_into_particles),
                   rel_gap(to_particles_from_grid, to_particles_into_particles),
                   rel_gap(to_grid_from_particles, to_grid_into_grid)});
}

Transfer::Transfer(const Device& device, const TransferParams& params)
    : device_(device), params_(params), ws_(device) {
  validate(params_);
  for (auto& b : s_u32_) b.set_device(device);
  for (auto& b : s_f32_) b.set_device(device);
  for (auto& b : c_f32_) b.set_device(device);
  for (auto& b : deposit_sums_) b.set_device(device);
  deposit_cells_.set_device(device);
  deposit_received_ = DeviceBuffer<int64_t>(device, 1);
  deposit_received_.fill_zero();
  p_moved_.set_device(device);
  room_count_.set_device(device);
  room_offset_.set_device(device);
  passes_.set_device(device);
  occ_.set_device(device);
  d2_.set_device(device);
  d2_tmp_.set_device(device);
  edt_z_.set_device(device);
  edt_v_.set_device(device);
  sums_ = DeviceBuffer<TransferSums>(device, 1);
  sums_.fill_zero();
  sums_ptr_ = sums_.data();
}

void Transfer::ensure_samples(int64_t n) {
  for (auto& b : s_u32_) b.resize(size_t(n));
  for (auto& b : s_f32_) b.resize(size_t(n));
}
void Transfer::ensure_cells(int64_t n) {
  for (auto& b : c_f32_) b.resize(size_t(n));
  if (deposit_cells_.capacity() == n) return;
  // The deposit's sums and list are zero between passes (DepositScratch): zeroed once here.
  for (auto& b : deposit_sums_) {
    b.resize(size_t(n));
    b.fill_zero();
  }
  deposit_cells_.ensure(n);
}
void Transfer::ensure_particles(int64_t n) { p_moved_.resize(size_t(n)); }

TransferRecord Transfer::step(const SampleView& samples, BristleLoad& load, ParticleStore& particles,
                              const TransferEnv& env) {
  WB_PROFILE_SCOPE("transfer.step");
  TransferRecord rec;
  rec.step = step_index_;
  {
    WB_PROFILE_SCOPE("transfer.capacity");
    update_capacity(samples, load, env);
  }
  if (env.dt > 0.f) {
    WB_PROFILE_SCOPE("transfer.share");
    share_contact(samples, load, env);
  }
  if (env.dt > 0.f) {  // also with wick_rate 0: the swept contact's sink is solved there
    WB_PROFILE_SCOPE("transfer.wick");
    wick(samples, load, env.dt);
  }
  {
    WB_PROFILE_SCOPE("transfer.absorb");
    absorb(samples, load, particles, env.dt);
  }
  {
    WB_PROFILE_SCOPE("transfer.distance");
    update_distance(samples, env);
  }
  {
    WB_PROFILE_SCOPE("transfer.to_grid");
    particles_to_grid(particles, env);
  }
  plan_particles(&samples, &load, particles, env, /*compact=*/true, /*candidates=*/true);
  ++step_index_;
  return rec;
}

void Transfer::collect(TransferRecord& rec) {
  WB_REQUIRE(sums_ptr_ == sums_.data(), "Transfer::collect: the sums go to the caller's record (set_sums)");
  TransferSums s{};
  sums_.copy_to_host(&s, 1);
  sums_.fill_zero();
  finish(s, true, rec);
  add_sums(s, double(params_.cell_mass()), rec);
}

void Transfer::add_sums(const TransferSums& s, double cm, TransferRecord& rec) {
  rec.absorbed_count += s.absorb_counts[0];
  rec.bleeding_count += s.absorb_counts[1];
  rec.absorbed_from_particles += s.absorbed_from_particles;
  rec.absorbed_into_bristles += s.absorbed_into_bristles;
  rec.emitted_from_bristles += s.emitted_from_bristles;
  rec.emitted_into_particles += s.emitted_into_particles;
  rec.to_particles_from_grid += s.to_particles_from_grid * cm;
  rec.to_particles_into_particles += s.to_particles_into_particles;
  rec.to_grid_count += s.to_grid_count + s.to_grid_at_moves;
  rec.to_grid_at_moves += s.to_grid_at_moves;
  rec.to_grid_from_particles += s.to_grid_from_particles;
  rec.to_grid_into_grid += s.to_grid_into_grid * cm;
}

void Transfer::update_capacity(const SampleView& samples, BristleLoad& load, const TransferEnv& env) {
  validate(env);
  WB_REQUIRE(load.device() == device_, "Transfer: the bristle load lives on another device");
  WB_REQUIRE(samples.count() == load.size(),
             "Transfer: " + std::to_string(samples.count()) + " samples but a load of " + std::to_string(load.size()));
  const PaintWindowView& pw = env.paint;
  const CellField psi{env.psi, pw.nx, pw.ny, pw.nz, pw.ox, pw.oy, pw.oz};
  const CellField density{pw.density, pw.nx, pw.ny, pw.nz, pw.ox, pw.oy, pw.oz};
  const CellField dryness{pw.dryness, pw.nx, pw.ny, pw.nz, pw.ox, pw.oy, pw.oz};
  transfer_capacity(device_, samples, load.view(), psi, density, dryness, params_, env.floor_z,
                    env.dry_threshold, env.dt);
}

void Transfer::share_contact(const SampleView& samples, BristleLoad& load, const TransferEnv& env) {
  const PaintWindowView& pw = env.paint;
  if (samples.count() == 0 || params_.split <= 0.f) return;
  passes_.resize(size_t(pw.nx) * size_t(pw.ny));
  passes_.fill_zero();
  const BristleLoadView lv = load.view();
  transfer_contact_paths(device_, samples, lv, env.dt, pw.ox, pw.oy, pw.nx, pw.ny, passes_.data());
  transfer_contact_share(device_, samples, lv, env.dt, pw.ox, pw.oy, pw.nx, pw.ny, passes_.data(), params_.split);
}

void Transfer::wick(const SampleView& samples, BristleLoad& load, float dt) {
  const int64_t ns = samples.count();
  WB_REQUIRE(ns == load.size(), "Transfer::wick: " + std::to_string(ns) + " samples but a load of " +
                                    std::to_string(load.size()));
  WB_REQUIRE(std::isfinite(dt) && dt >= 0.f, "Transfer::wick: dt must be finite and >= 0");
  if (ns == 0 || dt == 0.f) return;
  ensure_samples(ns);
  WickScratch w{};
  for (int k = 0; k < 2; ++k) {
    w.a[k] = s_f32_[4 * k].data();
    w.e[k] = s_f32_[4 * k + 1].data();
    w.c[k] = s_f32_[4 * k + 2].data();
    w.d[k] = s_f32_[4 * k + 3].data();
  }
  w.g = s_f32_[8].data();
  const BristleLoadView lv = load.view();
  const float k_dt = params_.wick_rate * dt, k_slide = params_.wick_slide;
  // The same ten launches every step of a stroke: on CUDA one graph's replay.
  const uint64_t key = launch_key({launch_key_of(samples.x), launch_key_of(samples.v), launch_key_of(lv.m),
                                   launch_key_of(lv.capacity), launch_key_of(w.a[0]), uint64_t(samples.bristles),
                                   uint64_t(samples.per_bristle), launch_key_of(k_dt), launch_key_of(k_slide),
                                   launch_key_of(dt)});
  wick_graph_.run(device_, key, [&] {
    transfer_wick(device_, samples, lv, samples.bristles, samples.per_bristle, k_dt, k_slide, dt, w);
  });
}

void Transfer::absorb(const SampleView& samples, BristleLoad& load, ParticleStore& particles, float dt) {
  const int64_t ns = samples.count(), np = particles.size();
  WB_REQUIRE(ns == load.size(), "Transfer::absorb: " + std::to_string(ns) + " samples but a load of " +
                                    std::to_string(load.size()));
  WB_REQUIRE(particles.device() == device_, "Transfer: the particles live on another device");
  WB_REQUIRE(std::isfinite(dt) && dt >= 0.f, "Transfer::absorb: dt must be finite and >= 0");
  ensure_samples(ns);
  ensure_particles(np);
  for (auto& b : s_f32_) b.fill_zero();
  s_u32_[0].fill_zero();
  s_u32_[2].fill_zero();
  p_moved_.fill_zero();
  AbsorbScratch a{};
  a.ticket = s_u32_[0].data();
  a.claimed = s_f32_[0].data();
  a.acc_m = s_f32_[1].data();
  for (int c = 0; c < 3; ++c) a.acc_c[c] = s_f32_[2 + c].data();
  a.acc_b = s_f32_[5].data();
  a.acc_oil = s_f32_[6].data();
  a.bl_w = s_f32_[7].data();
  for (int c = 0; c < 3; ++c) a.bl_c[c] = s_f32_[8 + c].data();
  a.bl_b = s_f32_[11].data();
  a.bl_n = s_u32_[2].data();
  a.moved = p_moved_.data();
  a.counters = sums_ptr_->absorb_counts;  // address only: the counts accumulate in the record
  const BristleLoadView lv = load.view();
  if (np > 0 && ns > 0) {
    transfer_absorb(device_, particles.view(), samples, lv, a, params_, dt, step_index_);
    transfer_absorb_apply(device_, lv, a);
  }
  reduce_sum_add_into(device_, p_moved_.data(), np, sum_field(&TransferSums::absorbed_from_particles), ws_);
  reduce_sum_add_into(device_, a.acc_m, ns, sum_field(&TransferSums::absorbed_into_bristles), ws_);
}

void Transfer::update_distance(const SampleView& samples, const TransferEnv& env) {
  validate(env);
  const PaintWindowView& pw = env.paint;
  const int B = params_.distance_block;
  const int margin = int(std::ceil(env.D0 / float(B))) + 1;
  DistanceBlocks db{};
  // One block more on each axis for the lattice's shift.
  db.bx = (pw.nx + B - 1) / B + 1 + 2 * margin;
  db.by = (pw.ny + B - 1) / B + 1 + 2 * margin;
  db.bz = (pw.nz + B - 1) / B + 1 + 2 * margin;
  db.block = B;
  db.margin = margin;
  db.D0 = env.D0;
  // The lattice lies on the brush: its blocks' edges at the anchor plus whole blocks. It travels
  // with the bristles, so the blocks they mark, and the distance, move with them as the brush
  // moves; a lattice held by the window (or shifted along a sequence over the steps) has the
  // marked blocks change as the bristles cross its edges, and the D0 front jump by up to a block
  // at moments set by the lattice, not the paint: ridges across a slow stroke.
  const double o[3] = {double(pw.ox), double(pw.oy), double(pw.oz)},
               anchor[3] = {env.lattice_anchor.x, env.lattice_anchor.y, env.lattice_anchor.z};
  float sh[3];
  for (int c = 0; c < 3; ++c) {
    const double u = (o[c] - anchor[c]) / double(B);
    sh[c] = float((u - std::floor(u)) * double(B));
  }
  db.shift = Vec3(sh[0], sh[1], sh[2]);
  const int64_t total = int64_t(db.bx) * db.by * db.bz;
  WB_REQUIRE(total < (int64_t(1) << 28), "Transfer: the distance field would need " + std::to_string(total) +
                                             " blocks; raise distance_block or lower D0");
  occ_.resize(size_t(total));
  d2_.resize(size_t(total));
  d2_tmp_.resize(size_t(total));
  edt_v_.resize(size_t(total));
  edt_z_.resize(size_t(2 * total));
  occ_.fill_zero();
  db.d = d2_.data();
  transfer_distance_occupancy(device_, samples, db, occ_.data(), pw.ox, pw.oy, pw.oz);
  transfer_distance_init(device_, occ_.data(), d2_.data(), total);
  // Separable exact squared distance transform: x (d2 -> tmp), y (tmp -> d2), z (d2 -> tmp), whose
  // pass takes the roots.
  transfer_distance_pass(device_, db, 0, d2_.data(), d2_tmp_.data(), edt_v_.data(), edt_z_.data());
  transfer_distance_pass(device_, db, 1, d2_tmp_.data(), d2_.data(), edt_v_.data(), edt_z_.data());
  transfer_distance_pass(device_, db, 2, d2_.data(), d2_tmp_.data(), edt_v_.data(), edt_z_.data());
  d2_.swap(d2_tmp_);
  db.d = d2_.data();
  blocks_ = db;
}

DistanceBlocks Transfer::distance_view() {
  WB_REQUIRE(blocks_.d != nullptr, "Transfer: update_distance has not run");
  return blocks_;
}

std::vector<float> Transfer::distance_to_host() {
  const DistanceBlocks db = distance_view();
  std::vector<float> d = d2_.to_host();
  for (float& v : d) v = v >= kFarDistance2 ? 1e30f : v * float(db.block);
  return d;
}

void Transfer::particles_to_grid(ParticleStore& particles, const TransferEnv& env) {
  validate(env);
  const DistanceBlocks db = env.only_leaving ? DistanceBlocks{} : distance_view();
  WB_REQUIRE(env.only_leaving || db.D0 == env.D0, "Transfer: the distance field was built for another D0");
  const int64_t np = particles.size(), nc = env.paint.size();
  ensure_cells(nc);
  ensure_particles(np);
  p_moved_.fill_zero();
  DepositScratch acc{};
  acc.rho = deposit_sums_[0].data();
  for (int c = 0; c < 3; ++c) acc.c[c] = deposit_sums_[1 + c].data();
  acc.b = deposit_sums_[4].data();
  acc.oil = deposit_sums_[5].data();
  acc.dryness = deposit_sums_[6].data();
  acc.cells = deposit_cells_.view();
  acc.received = deposit_received_.data();
  acc.moved = p_moved_.data();
  acc.counter = sum_field(env.only_leaving ? &TransferSums::to_grid_at_moves : &TransferSums::to_grid_count);
  acc.keep = env.keep;
  acc.only_leaving = env.only_leaving;
  acc.surface = env.surface;
  if (np > 0) {
    transfer_to_grid_mark(device_, particles.view(), env.paint, db, acc, params_, env.dry_threshold);
    // Density units in to_grid_into_grid; collect() turns them into kg.
    transfer_to_grid_apply(device_, env.paint, acc, sum_field(&TransferSums::to_grid_into_grid));
    deposit_cells_.clear_count();
  }
  reduce_sum_add_into(device_, p_moved_.data(), np, sum_field(&TransferSums::to_grid_from_particles), ws_);
}

void Transfer::emit(const SampleView& samples, BristleLoad& load, ParticleStore& particles, const TransferEnv& env,
                    TransferRecord& rec) {
  make_particles(&samples, &load, particles, env, /*compact=*/false, /*candidates=*/false, rec);
}

void Transfer::grid_to_particles(ParticleStore& particles, const TransferEnv& env, TransferRecord& rec) {
  make_particles(nullptr, nullptr, particles, env, /*compact=*/false, /*candidates=*/true, rec);
}

void Transfer::make_particles(const SampleView* samples, BristleLoad* load, ParticleStore& particles,
                              const TransferEnv& env, bool compact, bool candidates, TransferRecord& rec) {
  plan_particles(samples, load, particles, env, compact, candidates);
  if (!planned_) return;
  uint32_t ends[3];
  mem::copy_to_host(device_, ends, sums_ptr_->room_ends, sizeof(ends));  // a stage called alone: its own read
  finish_particles(ends, true, rec);
}

void Transfer::plan_particles(const SampleView* samples, BristleLoad* load, ParticleStore& particles,
                              const TransferEnv& env, bool compact, bool candidates) {
  planned_.reset();  // one left by an exception before its finish moved nothing
  const int64_t nk = compact ? particles.size() : 0;
  const int64_t ns = samples ? samples->count() : 0;
  if (samples)
    WB_REQUIRE(ns == load->size(), "Transfer::emit: " + std::to_string(ns) + " samples but a load of " +
                                       std::to_string(load->size()));
  DistanceBlocks db{};
  if (candidates) {
    validate(env);
    db = distance_view();
    WB_REQUIRE(db.D0 == env.D0, "Transfer: the distance field was built for another D0");
  }
  const int64_t nc = candidates ? env.paint.size() : 0;
  const int64_t n = nk + ns + nc;
  if (n == 0) return;
  WB_PROFILE_SCOPE("transfer.room");
  room_count_.resize(size_t(n));
  room_offset_.resize(size_t(n));
  uint32_t* count = room_count_.data();
  uint32_t* offset = room_offset_.data();
  if (nk > 0) particles_keep_flags(device_, particles.dead.data(), particles.m.data(), count, nk);
  if (ns > 0) {
    ensure_samples(ns);
    const EmitScratch e = emit_scratch();
    transfer_emit_count(device_, *samples, load->view(), params_, env.dt, count + nk, e.mass_each, e.swept_each,
                        e.swept_n);
  }
  if (nc > 0) {
    ensure_cells(nc);
    transfer_grid_count(device_, env.paint, db, env.keep, params_, env.dry_threshold, count + nk + ns);
  }
  exclusive_scan_into(device_, count, offset, n, ws_);
  // The three ends go into the record's sums: they come back with them (the simulator's step
  // record, or collect), and finish_particles sizes the store by them.
  transfer_room_ends(device_, count, offset, n, nk, nk + ns, sums_ptr_->room_ends);
  planned_ = Planned{samples ? *samples : SampleView{}, load, &particles, env, nk, ns, step_index_, compact, candidates};
}

void Transfer::finish(const TransferSums& s, bool create, TransferRecord& rec) {
  if (planned_) finish_particles(s.room_ends, create, rec);
}

void Transfer::finish_particles(const uint32_t ends[3], bool create, TransferRecord& rec) {
  const Planned pl = *planned_;
  planned_.reset();
  ParticleStore& particles = *pl.particles;
  const int64_t nk = pl.nk, ns = pl.ns;
  uint32_t* count = room_count_.data();
  uint32_t* offset = room_offset_.data();
  NewBatch emission{}, cells{};
  {
    WB_PROFILE_SCOPE("transfer.room");
    const int64_t kept = pl.compact ? int64_t(ends[0]) : particles.size();
    if (kept < nk) particles.remove_dead(offset, kept);
    if (!create) return;  // the counts stay where they were: the next step makes them
    const int64_t want_emitted = int64_t(ends[1]) - int64_t(ends[0]), want_cells = int64_t(ends[2]) - int64_t(ends[1]);
    int64_t room = std::max<int64_t>(particles.limit() - kept, 0);
    const int64_t n_emitted = std::min(want_emitted, room);
    room -= n_emitted;
    const int64_t n_cells = std::min(want_cells, room);
    if (ns > 0) rec.emission_dropped = want_emitted - n_emitted;
    if (pl.candidates) rec.to_particles_dropped = want_cells - n_cells;
    const int64_t first = n_emitted + n_cells > 0 ? particles.append_uninitialised(n_emitted + n_cells) : kept;
    emission = NewBatch{count + nk, offset + nk, int64_t(ends[0]), first, n_emitted};
    cells = NewBatch{count + nk + ns, offset + nk + ns, int64_t(ends[1]), first + n_emitted, n_cells};
  }
  if (emission.n > 0) {
    WB_PROFILE_SCOPE("transfer.emit");
    fill_emission(pl.samples, *pl.load, particles, pl.env, emission, pl.step);
    rec.emitted_count = emission.n;
  }
  if (cells.n > 0) {
    WB_PROFILE_SCOPE("transfer.to_particles");
    fill_candidates(particles, pl.env, cells);
    rec.to_particles_count = cells.n;
  }
}

void Transfer::fill_emission(const SampleView& samples, BristleLoad& load, ParticleStore& particles,
                             const TransferEnv& env, const NewBatch& batch, int64_t step) {
  const int64_t ns = samples.count();
  const ParticleView pv = particles.view();
  const EmitScratch e = emit_scratch();
  float* emitted = e.emitted;
  transfer_emit_fill(device_, samples, load.view(), pv, batch, e.mass_each, e.swept_each, e.swept_n, step,
                     params_, env.floor_z, env.dt, env.paint, env.dry_threshold, emitted);
  reduce_sum_add_into(device_, emitted, ns, sum_field(&TransferSums::emitted_from_bristles), ws_);
  reduce_sum_add_into(device_, pv.m + batch.first, batch.n, sum_field(&TransferSums::emitted_into_particles), ws_);
}

void Transfer::fill_candidates(ParticleStore& particles, const TransferEnv& env, const NewBatch& batch) {
  const int64_t nc = env.paint.size();
  const ParticleView pv = particles.view();
  float* demand = c_f32_[0].data();
  float* removed = c_f32_[1].data();
  c_f32_[0].fill_zero();
  transfer_grid_emit(device_, env.paint, env.velocity, pv, batch, params_, env.dry_threshold, demand);
  transfer_grid_clamp(device_, env.paint, demand, removed);
  transfer_grid_finish(device_, pv, batch.first, batch.n, env.paint, demand, params_, env.dry_threshold);
  // Density units here; collect() turns them into kg.
  reduce_sum_add_into(device_, removed, nc, sum_field(&TransferSums::to_particles_from_grid), ws_);
  reduce_sum_add_into(device_, pv.m + batch.first, batch.n, sum_field(&TransferSums::to_particles_into_particles), ws_);
}

}  // namespace wb
