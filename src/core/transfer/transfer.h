// Liquid transfer stage (paper §5, Eq. 12-16; DESIGN step 8). Transfer::step runs, in order:
//   update_capacity (Eq. 12-13) -> absorb (Eq. 14, colour bleeding) -> update_distance ->
//   particles_to_grid (Eq. 16) -> compact -> emit (§5.1) -> grid_to_particles (Eq. 15)
// (the last three sized by one scan whose three ends come back with the record's sums, and made
// by finish once they have)
// and returns what each transfer moved (TransferRecord; PaintBooks keeps the budget).
// The stage functions validate their input and dispatch to wb::cpu or wb::cuda (transfer_impl.h).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/brush/bristle_fields.h"
#include "core/canvas/window.h"
#include "core/exec/buffer.h"
#include "core/exec/device.h"
#include "core/exec/dispatch.h"
#include "core/exec/graph.h"
#include "core/exec/hd.h"
#include "core/exec/touch_list.h"
#include "core/exec/workspace.h"
#include "core/particles/mac_sample.h"
#include "core/particles/particle_fields.h"
#include "core/particles/particle_store.h"
#include "core/transfer/bristle_load.h"
#include "core/transfer/bristle_particle_kernels.h"
#include "core/transfer/grid_particle_kernels.h"
#include "core/transfer/transfer_params.h"

namespace wb {

/// What the transfer reads besides the samples, the load and the particles.
struct TransferEnv {
  PaintWindowView paint{};     ///< the active window's paint; §5.2 changes density, pigment, oil, dryness
  const float* psi = nullptr;  ///< bristle density psi on the same window (Brush::rasterize); null: psi = 0
  MacView velocity{};          ///< window MAC velocity for new grid particles; u == nullptr: at rest
  float floor_z = 0.f;         ///< canvas surface height, cells (ParticleParams::floor_z)
  float dry_threshold = 0.95f; ///< dryness at which paint is solid (GridParams::dry_threshold)
  float D0 = 50.f;             ///< particle range around the bristles, cells (ParticleParams::D0)
  float dt = 0.f;              ///< step length, s, for the wicking along the bristles (0: none)
  /// A point that moves with the brush (canvas cells): the distance blocks' lattice is laid on
  /// it, so that it travels with the bristles (docs/TRANSFER.md "Ribs on slow strokes").
  Vec3 lattice_anchor{};
  /// Window box the particles may stay in (off: the whole window); the simulator sets it every
  /// step and, before the window moves, to the part that stays (docs/TRANSFER.md).
  KeepBox keep{};
  /// Eq. 16 for the particles outside `keep` only (the window is about to move off them); the
  /// others wait for the step's own pass, and no distance field is read.
  bool only_leaving = false;
  /// Top of the paint per window column (canvas z; at or above the solid's; null: unknown). A
  /// particle Eq. 16 returns above it lands on it: the grid has no gravity for paint in air
  /// cells, so paint returned in flight would hang there (docs/TRANSFER.md "Returning in flight").
  const float* surface = nullptr;
};

/// What one step's transfers moved, kg, each measured on both sides (source / destination),
/// so that the books close per transfer.
struct TransferRecord {
  int64_t step = 0;
  // Bristle <- particle (Eq. 14).
  int64_t absorbed_count = 0;
  double absorbed_from_particles = 0;
  double absorbed_into_bristles = 0;
  int64_t bleeding_count = 0;  ///< particles that exchanged colour only (saturated sample or limit)
  // Bristle -> particle (§5.1 emission).
  int64_t emitted_count = 0;
  double emitted_from_bristles = 0;
  double emitted_into_particles = 0;
  int64_t emission_dropped = 0;  ///< particles not emitted because the store was at its limit
  // Grid -> particle (Eq. 15).
  int64_t to_particles_count = 0;
  double to_particles_from_grid = 0;
  double to_particles_into_particles = 0;
  int64_t to_particles_dropped = 0;  ///< candidates not created because the store was at its limit
  // Particle -> grid (Eq. 16).
  int64_t to_grid_count = 0;
  int64_t to_grid_at_moves = 0;  ///< of them, the particles a window move left (only_leaving)
  double to_grid_from_particles = 0;
  double to_grid_into_grid = 0;

  /// Largest relative mismatch |source - destination| / max(source, destination) of the four.
  double max_closure_error() const;
  /// Net change of each reservoir this step, kg.
  double bristle_change() const { return absorbed_into_bristles - emitted_from_bristles; }
  double particle_change() const {
    return emitted_into_particles + to_particles_into_particles - absorbed_from_particles - to_grid_from_particles;
  }
  double grid_change() const { return to_grid_into_grid - to_particles_from_grid; }
};

/// The part of a TransferRecord the device computes (sums and counts), accumulated on the device
/// by every stage call and brought to the host in one copy by Transfer::collect.
struct TransferSums {
  double absorbed_from_particles, absorbed_into_bristles;
  double emitted_from_bristles, emitted_into_particles;
  double to_particles_from_grid, to_particles_into_particles;
  double to_grid_from_particles, to_grid_into_grid;
  int32_t absorb_counts[2];  ///< absorbed, bleeding (AbsorbScratch::counters)
  int32_t to_grid_count;     ///< DepositScratch::counter of the step's passes ...
  int32_t to_grid_at_moves;  ///< ... and of a window move's (only_leaving)
  /// The new particles' scan's three ends (survivors; and the emission; and Eq. 15's candidates):
  /// the counts the store is sized by (Transfer::finish).
  uint32_t room_ends[3];
};

/// Scratch of the absorption pass, per sample (accumulators) and per particle (moved mass).
/// The wick's per-sample scratch: each bristle's tridiagonal rows (a s_{i-1} + b s_i + c s_{i+1}
/// = d, kept as a, c, d and the row sum e = a + b + c) in two copies for the cyclic reduction's
/// passes, and each edge's conductance g.
struct WickScratch {
  float* a[2];
  float* e[2];
  float* c[2];
  float* d[2];
  float* g;
};

struct AbsorbScratch {
  uint32_t* ticket;  ///< particles that asked sample j this step
  float* claimed;    ///< mass claimed from sample j this step (capacity test)
  float* acc_m;      ///< absorbed mass
  float* acc_c[3];   ///< sum m_k c_k of absorbed particles
  float* acc_b;      ///< sum m_k brightness(c_k)
  float* acc_oil;    ///< sum m_k oil_k
  float* bl_w;       ///< sum of bleeding weights e
  float* bl_c[3];    ///< sum e c_k
  float* bl_b;       ///< sum e brightness(c_k)
  uint32_t* bl_n;    ///< particles bleeding into sample j (counted into counters[1] by the apply pass)
  float* moved;      ///< per particle: mass absorbed (0 otherwise)
  int32_t* counters; ///< [0] absorbed, [1] bleeding
};

/// Per-cell accumulators of Eq. 16 (density units = cell fractions), in the fixed point of
/// to_fixed: integer sums do not depend on the order the particles arrive in, so the same
/// particles always give the same cells, on any thread count (a save of the same state is the
/// same file). They are zero between passes: the mark pass lists each cell it reaches once, and
/// the apply pass visits only those and zeroes what it read, so a pass costs in proportion to
/// the particles returned, not to the window.
struct DepositScratch {
  int64_t* rho;     ///< sum m_k W / cell_mass
  int64_t* c[3];    ///< sum (m_k W / cell_mass) c_k
  int64_t* b;       ///< sum (m_k W / cell_mass) brightness(c_k)
  int64_t* oil;
  int64_t* dryness;
  TouchList cells;    ///< the cells reached (core/exec/touch_list.h)
  int64_t* received;  ///< the density the listed cells received (to_fixed of each cell's add)
  float* moved;       ///< per particle: mass sent to the grid
  int32_t* counter;
  KeepBox keep;             ///< particles outside it are deposited regardless (TransferEnv::keep)
  bool only_leaving;        ///< TransferEnv::only_leaving
  const float* surface;     ///< TransferEnv::surface
};

/// A batch of new particles (§5.1's emission or Eq. 15's candidates): count[j] from source j,
/// laid at store index first + offset[j] - base, where offset is the exclusive scan the batch
/// shares with what precedes it (Transfer::make_particles); the first n exist, the rest were
/// dropped at the store's limit.
struct NewBatch {
  const uint32_t* count;
  const uint32_t* offset;
  int64_t base;   ///< offset of the batch's first slot in the shared scan
  int64_t first;  ///< store index of the batch's first particle
  int64_t n;      ///< particles appended for the batch
  WB_HD int64_t slot(int64_t j) const { return int64_t(offset[j]) - base; }
};

class Transfer {
 public:
  explicit Transfer(const Device& device, const TransferParams& params = {});

  const Device& device() const { return device_; }
  TransferParams& params() { return params_; }
  const TransferParams& params() const { return params_; }
  int64_t steps() const { return step_index_; }

  /// One transfer step (§5): every stage below in order, queued without a host read. The
  /// compaction of the particle store and the room of the emission and of Eq. 15 come from one
  /// scan, whose ends go into the sums (TransferSums::room_ends); the store is compacted and the
  /// new particles made by finish() once the sums are read (the caller's record, or collect()).
  /// The particles' `nearest` must come from SampleGrid::query_nearest on these samples this
  /// step (the absorption candidate; the distance is re-measured here).
  TransferRecord step(const SampleView& samples, BristleLoad& load, ParticleStore& particles, const TransferEnv& env);
  /// Ends the last step() with the sums that came back: removes the dead particles and, where
  /// `create`, makes the new ones (as many as the store's limit allows, emission first; the rest
  /// counted as dropped in rec). Without `create` the paint they would take stays where it is
  /// (the next step makes them): the simulator's step that found non-finite values. The new
  /// particles' sums go into the device's accumulation after the read: they come back with the
  /// next record. Nothing to do where no step is waiting.
  void finish(const TransferSums& s, bool create, TransferRecord& rec);
  /// Reads the sums and counts the device accumulated since the last collect (every stage call's)
  /// in one host read, ends the last step() with them (finish) and adds them into rec.
  void collect(TransferRecord& rec);
  /// Where the stages accumulate their sums: a TransferSums on this device that the caller
  /// reads with more of its own in one copy (the simulator's step record), then passes to
  /// add_sums and zeroes; nullptr: the transfer's own, read by collect().
  void set_sums(TransferSums* device_sums) { sums_ptr_ = device_sums ? device_sums : sums_.data(); }
  /// rec += s (the device's densities in kg).
  static void add_sums(const TransferSums& s, double cell_mass, TransferRecord& rec);

  // --- stages (public for tests and profiling; step() calls them in this order) ---
  /// Eq. 12-13 for every sample: load.potential, load.capacity, load.radius.
  void update_capacity(const SampleView& samples, BristleLoad& load, const TransferEnv& env);
  /// Wicking (docs/TRANSFER.md): the load flows along each bristle from fuller to emptier
  /// samples (saturation m / M'), implicitly over dt; colour and oil go with it.
  void wick(const SampleView& samples, BristleLoad& load, float dt);
  /// Swept contact: samples that sweep the same canvas column in one step share the deposit
  /// of their sequence of passes (pass_share), so that a layer is laid once, not once per row
  /// of bristles.
  void share_contact(const SampleView& samples, BristleLoad& load, const TransferEnv& env);
  /// Eq. 14: particles within R_j of their nearest sample j join it while m_j < M_j (at most
  /// absorb_limit taken per sample), else bleed colour; a sample touching a surface takes a
  /// particle of its film under the path it slid over dt with the chance of the share of the
  /// particle's chord that path swept (swept_chord_share, film_pickup). Absorbed particles are
  /// flagged dead. The stages that take a record fill its host-known fields; their sums wait for
  /// collect().
  void absorb(const SampleView& samples, BristleLoad& load, ParticleStore& particles, float dt);
  /// The coarse distance from every window block to the bristles (decides "within D0").
  void update_distance(const SampleView& samples, const TransferEnv& env);
  /// Eq. 16: live particles slower than slow_speed in blocks farther than D0 go to the grid.
  void particles_to_grid(ParticleStore& particles, const TransferEnv& env);
  /// §5.1: samples above (1 + epsilon) M_j emit particles in their lower hemisphere, and samples
  /// sliding over a surface leave the swept part of their paint along their path (env.dt).
  void emit(const SampleView& samples, BristleLoad& load, ParticleStore& particles, const TransferEnv& env,
            TransferRecord& rec);
  /// Eq. 15: cells within D0 of the bristles become particles (27 stratified candidates).
  void grid_to_particles(ParticleStore& particles, const TransferEnv& env, TransferRecord& rec);

  /// The distance field of the last update_distance (device pointers valid until the next).
  DistanceBlocks distance_view();
  /// Host copy of the block distances (cells) of the last update_distance, for tests and images.
  std::vector<float> distance_to_host();

 private:
  /// New particles from the samples (§5.1, when `samples` is given) and from the cells near the
  /// bristles (Eq. 15, when `candidates`), after removing the dead ones (when `compact`). One
  /// exclusive scan over [keep flags | emission counts | candidate counts] gives the survivors'
  /// slots and both batches' offsets, and one host read its three prefix ends: the counts the
  /// store is sized by. As many as the store's limit allows are appended (emission first, sources
  /// in index order); the rest are counted as dropped in rec.
  void make_particles(const SampleView* samples, BristleLoad* load, ParticleStore& particles, const TransferEnv& env,
                      bool compact, bool candidates, TransferRecord& rec);
  /// make_particles up to the scan's ends (queued into the sums); finish_particles the rest.
  void plan_particles(const SampleView* samples, BristleLoad* load, ParticleStore& particles, const TransferEnv& env,
                      bool compact, bool candidates);
  void finish_particles(const uint32_t ends[3], bool create, TransferRecord& rec);
  /// What plan_particles queued, for finish_particles.
  struct Planned {
    SampleView samples;
    BristleLoad* load;
    ParticleStore* particles;
    TransferEnv env;
    int64_t nk, ns;  ///< the survivors' and the emission's sources
    int64_t step;    ///< the step index the emission's random draws use
    bool compact, candidates;
  };
  std::optional<Planned> planned_;
  void fill_emission(const SampleView& samples, BristleLoad& load, ParticleStore& particles, const TransferEnv& env,
                     const NewBatch& batch, int64_t step);
  /// The emission's per-sample scratch, written by its count and read by its fill.
  struct EmitScratch {
    float* mass_each;
    float* emitted;
    float* swept_each;
    uint32_t* swept_n;
  };
  EmitScratch emit_scratch() {
    return {s_f32_[0].data(), s_f32_[1].data(), s_f32_[2].data(), s_u32_[1].data()};
  }
  void fill_candidates(ParticleStore& particles, const TransferEnv& env, const NewBatch& batch);
  void ensure_samples(int64_t n);
  void ensure_cells(int64_t n);
  void ensure_particles(int64_t n);

  Device device_;
  TransferParams params_;
  Workspace ws_;
  int64_t step_index_ = 0;
  // Per sample.
  DeviceBuffer<uint32_t> s_u32_[3];
  DeviceBuffer<float> s_f32_[12];
  LaunchGraph wick_graph_;  ///< the wick's passes, recorded (CUDA)
  // Per particle.
  DeviceBuffer<float> p_moved_;
  // make_particles: the counts and their scan (its ends go into the sums).
  DeviceBuffer<uint32_t> room_count_, room_offset_;
  // Per cell.
  DeviceBuffer<float> c_f32_[7];
  // Eq. 16's deposit (DepositScratch): its sums, zero between passes, the cells listed and
  // what they received.
  DeviceBuffer<int64_t> deposit_sums_[7];
  TouchListBuffers deposit_cells_;
  DeviceBuffer<int64_t> deposit_received_;
  // Distance blocks.
  DeviceBuffer<int32_t> occ_;
  DeviceBuffer<float> d2_, d2_tmp_, edt_z_;
  DeviceBuffer<int32_t> edt_v_;
  DistanceBlocks blocks_{};
  // Swept-contact passes per window column.
  DeviceBuffer<uint32_t> passes_;
  // The device's part of the record (one TransferSums), zeroed by collect(); or the caller's.
  DeviceBuffer<TransferSums> sums_;
  TransferSums* sums_ptr_ = nullptr;
  template <typename M>
  M* sum_field(M TransferSums::*field) {
    return &(sums_ptr_->*field);  // address arithmetic on the device pointer, no access
  }
};

// The transfer stage's backend drivers (transfer_impl.h), one list (core/exec/dispatch.h).
#define WB_TRANSFER_KERNELS(X)                                                                                       \
  X(void, transfer_capacity, (SampleView s, BristleLoadView load, CellField psi, CellField density,                  \
      CellField dryness, TransferParams prm, float floor_z, float dry_threshold, float dt),                          \
      (s, load, psi, density, dryness, prm, floor_z, dry_threshold, dt))                                             \
  X(void, transfer_contact_paths, (SampleView s, BristleLoadView load, float dt, int ox, int oy, int nx, int ny,     \
      uint32_t* passes), (s, load, dt, ox, oy, nx, ny, passes))                                                      \
  X(void, transfer_contact_share, (SampleView s, BristleLoadView load, float dt, int ox, int oy, int nx, int ny,     \
      const uint32_t* passes, float split), (s, load, dt, ox, oy, nx, ny, passes, split))                            \
  X(void, transfer_absorb, (ParticleView p, SampleView s, BristleLoadView load, AbsorbScratch a, TransferParams prm, \
      float dt, int64_t step_index), (p, s, load, a, prm, dt, step_index))                                           \
  X(void, transfer_absorb_apply, (BristleLoadView load, AbsorbScratch a), (load, a))                                 \
  X(void, transfer_wick, (SampleView s, BristleLoadView load, int bristles, int per, float k_dt, float k_slide,      \
      float dt, WickScratch w), (s, load, bristles, per, k_dt, k_slide, dt, w))                                      \
  X(void, transfer_distance_occupancy, (SampleView s, DistanceBlocks db, int32_t* occ, int ox, int oy, int oz),      \
      (s, db, occ, ox, oy, oz))                                                                                      \
  X(void, transfer_distance_init, (const int32_t* occ, float* d2, int64_t n), (occ, d2, n))                          \
  X(void, transfer_distance_pass, (DistanceBlocks db, int axis, const float* src, float* dst, int32_t* v, float* z), \
      (db, axis, src, dst, v, z))                                                                                    \
  X(void, transfer_to_grid_mark, (ParticleView p, PaintWindowView pw, DistanceBlocks db, DepositScratch acc,         \
      TransferParams prm, float dry_threshold), (p, pw, db, acc, prm, dry_threshold))                                \
  X(void, transfer_to_grid_apply, (PaintWindowView pw, DepositScratch acc, double* into_grid),                       \
      (pw, acc, into_grid))                                                                                          \
  X(void, transfer_emit_count, (SampleView s, BristleLoadView load, TransferParams prm, float dt, uint32_t* count,   \
      float* mass_each, float* swept_each, uint32_t* swept_n),                                                       \
      (s, load, prm, dt, count, mass_each, swept_each, swept_n))                                                     \
  X(void, transfer_emit_fill, (SampleView s, BristleLoadView load, ParticleView p, NewBatch batch,                   \
      const float* mass_each, const float* swept_each, const uint32_t* swept_n, int64_t step_index,                  \
      TransferParams prm, float floor_z, float dt, PaintWindowView pw, float dry_threshold, float* emitted),         \
      (s, load, p, batch, mass_each, swept_each, swept_n, step_index, prm, floor_z, dt, pw, dry_threshold, emitted)) \
  X(void, transfer_grid_count, (PaintWindowView pw, DistanceBlocks db, KeepBox keep, TransferParams prm,             \
      float dry_threshold, uint32_t* count), (pw, db, keep, prm, dry_threshold, count))                              \
  X(void, transfer_grid_emit, (PaintWindowView pw, MacView vel, ParticleView p, NewBatch batch, TransferParams prm,  \
      float dry_threshold, float* demand), (pw, vel, p, batch, prm, dry_threshold, demand))                          \
  X(void, transfer_room_ends, (const uint32_t* count, const uint32_t* offset, int64_t n, int64_t a, int64_t b,       \
      uint32_t* ends), (count, offset, n, a, b, ends))                                                               \
  X(void, transfer_grid_clamp, (PaintWindowView pw, float* demand_ratio, float* removed),                            \
      (pw, demand_ratio, removed))                                                                                   \
  X(void, transfer_grid_finish, (ParticleView p, int64_t first, int64_t n, PaintWindowView pw, const float* ratio,   \
      TransferParams prm, float dry_threshold), (p, first, n, pw, ratio, prm, dry_threshold))                        \
  X(void, transfer_product, (const float* a, const float* b, float* out, int64_t n), (a, b, out, n))                 \
  X(void, transfer_load_brightness, (BristleLoadView load, float* out), (load, out))                                 \
  X(void, transfer_load_dip, (BristleLoadView load, const float* exchange, Vec3 ryb, float oil, float level,         \
      int replace, float* added), (load, exchange, ryb, oil, level, replace, added))                                 \
  X(void, transfer_load_scale, (BristleLoadView load, float keep, float* change), (load, keep, change))
WB_DECLARE_KERNELS(WB_TRANSFER_KERNELS)

}  // namespace wb
