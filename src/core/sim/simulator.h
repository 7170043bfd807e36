// The simulator: one call of step() is one time step of the paper's Figure 4, with the
// stages called by name in the paper's order. The physics lives in the stage headers;
// this file only sequences them, times them and keeps the books.
#pragma once
#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/brush/brush.h"
#include "core/canvas/tile_store.h"
#include "core/exec/atomics.h"
#include "core/exec/device.h"
#include "core/exec/profile.h"
#include "core/exec/touch_list.h"
#include "core/exec/workspace.h"
#include "core/grid/grid.h"
#include "core/io/stroke.h"
#include "core/params/sim_params.h"
#include "core/particles/particle_store.h"
#include "core/particles/sample_grid.h"
#include "core/render/renderer.h"
#include "core/transfer/paint_books.h"
#include "core/transfer/transfer.h"

namespace wb {

struct SimConfig {
  Device device{};
  CanvasDims canvas{};
  /// Active window, cells. The paper's is 128 x 128 x 32 (§4.2); 160 holds the default round and
  /// flat brushes pressed and dragged with their particle zone (Simulator::place_window), which
  /// 128 cuts on most steps of the examples (docs/TRANSFER.md "The particle zone").
  Int3 window{160, 160, 32};
  BrushSpec brush{};
  SimParams params{};
  /// false: grid-only paint (no particles, no bristle-particle transfer), the paper's Fig. 7a/c.
  bool particles = true;
};

/// Counters a replay reports (stats JSON) and the studio shows.
struct SimCounters {
  int64_t steps = 0;
  int64_t substeps = 0;
  int64_t nonfinite_events = 0;  ///< steps whose state went non-finite and were contained
  int64_t particles_max = 0;
  /// Steps whose particle zone, at D0's floor, did not fit the window's kept box around the
  /// samples (the brush is too large for its window: Simulator::place_window) and whose window
  /// move returned particles to the grid.
  int64_t zone_cut_steps = 0;
  /// Step parts whose window was placed on the samples' box read back at once, not on the last
  /// step's box moved by the pen (that box, widened by its last miss, would reach the window's
  /// rim: a brush nearly as large as its window; step_part).
  int64_t box_reads = 0;
  /// Steps whose brush swept farther than the window holds, simulated in parts (step()), and
  /// the parts they took in all.
  int64_t split_steps = 0;
  int64_t step_parts = 0;
  /// The least room for D0 around the samples of the steps zone_cut_steps counts, cells.
  float zone_room_min = 1e30f;
  /// Particles returned to the grid because the window moved off them (deposit_leaving_particles):
  /// where the zone fits, only the slow ones beyond it that the step's own pass would return.
  int64_t returned_at_moves = 0;
  /// Pauses passed over by rest(): how many, and their seconds.
  int64_t rests = 0;
  double rest_seconds = 0.0;
  /// Particles not made because the store was at its limit (the parameter's, or what the memory
  /// budget leaves: check_memory): their paint stayed on the bristles or in the grid.
  int64_t particles_refused = 0;
};

/// The brush as the artist sees it (the studio's brush preview and paint swatch), read from
/// the device: each bristle's vertices relative to the ferrule in canvas axes, and its paint.
struct BrushPicture {
  int bristles = 0, vertices_per_bristle = 0;
  std::vector<Vec3> vertices;  ///< bristle-major, canvas axes, cells, the ferrule at the origin
  float canvas_z = 0.f;        ///< the canvas plane in those coordinates (minus the ferrule's height)
  std::vector<Vec3> ryb;       ///< per bristle: mass-weighted pigment of its samples (0 when dry)
  std::vector<float> fill;     ///< per bristle: load / potential capacity (Eq. 12), 0..~1
  Vec3 mean_ryb{};             ///< the whole brush's pigment, mass-weighted (0 when clean)
  float amount = 0.f;          ///< the whole brush's load / potential capacity
};

class Simulator {
 public:
  Simulator(const SimConfig& config, const BrushPose& initial_pose);

  const SimConfig& config() const { return config_; }
  const Device& device() const { return config_.device; }
  /// The painting. The stages' own objects are private: read them through the const views
  /// below; what changes them is this class's API (its Session and tests aside).
  const TileStore& canvas() const { return *canvas_; }
  const Brush& brush() const { return *brush_; }
  const Grid& grid() const { return *grid_; }
  const ParticleStore& particles() const { return particles_; }
  const BristleLoad& load() const { return *load_; }
  const PaintBooks& books() const { return books_; }
  Profiler& profiler() { return profiler_; }
  const Profiler& profiler() const { return profiler_; }
  const SimCounters& counters() const { return counters_; }
  /// The most particles the store may hold: the parameter's limit, or less where the memory
  /// budget leaves less room (check_memory).
  int64_t particle_limit() const { return particles_.limit(); }

  /// One time step of length dt (Figure 4): the brush runs `substeps` sub-steps ending at
  /// poses[0..substeps), then the paint (window, particles, joint fields, grid, FLIP/PIC,
  /// transfer) runs once over the whole step. A brush sweeping farther in the step than the
  /// window can hold around it (a flick) is simulated in as many parts of the step as keep each
  /// part's sweep inside the window, its sub-steps shared among them (docs/GRID.md "Flicks").
  void step(const BrushPose* poses, int substeps, float dt);
  void step(const BrushPose& pose, float dt) { step(&pose, 1, dt); }
  /// Puts the brush at rest at `pose` (a new stroke after a lift, or a teleport).
  void reset_brush(const BrushPose& pose);
  /// True when the last step left the paint at rest: no face of a painted cell carried paint
  /// faster than grid.rest_speed (the flow the step's advection started from).
  bool paint_at_rest() const;
  /// True when, at the end of the last step, the brush rested and wet paint ran across the canvas
  /// faster than kRunningPaint (10 cells/s, 2 mm/s: drips down an easel, an oily pool spreading),
  /// the box the resting brush's window slides after (docs/GRID.md "The window's walls").
  bool paint_running() const { return running_.has_value(); }
  /// A pause of `seconds` in which nothing moves, in one call instead of its steps: the particles
  /// go back into the grid (settle), every painted cell dries by the pause (Grid::dry) and the
  /// brush waits at rest at `pose`, where the pause ends.
  void rest(double seconds, const BrushPose& pose);

  // --- paint on the brush (the books enter what it gains or loses with the next step record) ---
  void load_paint(const PaintLoad& paint);  ///< a freshly loaded brush
  void dip(const PaintLoad& paint);         ///< dip a dirty brush into a well
  void wipe(float fraction);
  void clean();
  /// A palette event of a stroke file or the studio: dip, wipe, clean or dry (the one mapping).
  void apply(const StrokeEvent& e);

  /// The paint on the brush, sample by sample (a brush carried to another simulator of the same
  /// brush: the studio's palette).
  BristleLoadHost brush_paint() const;
  /// The brush takes this paint, sample by sample (brush_paint of a simulator with the same
  /// brush); the books record the change as paint that entered or left from outside.
  void set_brush_paint(const BristleLoadHost& paint);
  /// The brush's paint as one well (BristleLoad::mean_paint): what a recording that starts with
  /// this brush loads on every sample. A clean brush gives `clean` with no load.
  PaintLoad brush_mean_paint(const PaintLoad& clean);
  /// "Let it dry": flushes the window, dries every painted cell of the canvas, reloads.
  void dry_canvas();
  /// Primes the empty canvas (throws wb::Error if it holds paint) with a woven ground of the primer's pigment (ground.h); the books
  /// record it as paint that entered from outside. A smooth ground lays nothing.
  void lay_ground(const CanvasGround& ground, Vec3 primer_ryb);
  /// Puts every particle back into the grid (Eq. 16 for all) and writes the window to the
  /// canvas, so that the canvas alone holds the painting (before saving or a final render).
  void settle();
  /// Where the paint is now, kg.
  PaintCensus census();

  // --- the canvas as files, undo and the studio see it ---
  /// Runs `fn` on the canvas as it is when every paint comes to rest now (settle: the particles
  /// back into the grid by Eq. 16, the window written to the tiles), then puts the simulation back
  /// exactly as it was (window, particles, the tiles under the window): a session that saves
  /// replays like one that does not. Saves, exports and undo records see this canvas.
  void with_settled_canvas(const std::function<void(TileStore&)>& fn);
  /// A copy of the settled canvas on `device`, without tiles that are all zero.
  TileStore settled_canvas_copy(const Device& device);
  /// Writes the live window to the tiles without changing the simulation (its next scatter
  /// writes the same cells).
  void flush_window();
  /// Writes the canvas from outside (undo, redo, open, a kept canvas, a primed ground): `write`
  /// changes the tiles (the window written to them first), the window is read back from them and the paint in flight, which belonged
  /// to the canvas that was replaced, is dropped. The books record the difference of the census
  /// before and after as paint that entered or left from outside, wherever the tiles changed.
  void replace_canvas(const std::function<void(TileStore&)>& write);
  /// Liquid particles in flight.
  int64_t particle_count() const { return particles_.size(); }
  /// The particles in flight, for the renderer.
  ParticleOverlay particle_overlay();
  /// The brush's pose and paint now (a few small copies from the device; for the UI, not per step).
  BrushPicture brush_picture() const;
  /// Dried paint of the canvas as the brush sees it now (views into the current tile pool).
  SolidField solid_field();
  /// A replay's report, on the device (no host read): the cells of the `w` x `h` trace at
  /// (ox, oy) that a bristle touches now (within a cell of the canvas or dried paint), their count
  /// into *count, and the largest relative segment stretch into *stretch.
  void mark_brush_contacts(int32_t* trace, int w, int h, int ox, int oy, double* count, float* stretch);

 private:
  friend class Session;               // renders the live canvas and window, records undo from the tiles
  friend struct SimulatorTestAccess;  // tests poison and inspect the stages' state (tests/sim)
  /// The tiles and the live window as the renderer and undo records take them (Session).
  TileStore& tiles() { return *canvas_; }
  PaintWindow* live_window() { return &grid_->window().paint(); }
  void brush_stage(const BrushPose* poses, int substeps, float dt);
  void particle_stage(float dt);
  void deposit_leaving_particles(Int3 next_origin);
  /// The step's transfer sums added to rec and the census, from one read of step_sums_ (kept
  /// whole in last_record_). At a step's end (`step_end`) the read also ends the step's transfer
  /// (Transfer::finish: the store compacted and the new particles made, after the census's sums
  /// were queued: the paint they move is counted where it was).
  PaintCensus record_census(TransferRecord& rec, bool step_end);
  void joint_fields_stage();
  /// The raster's listed cells (and faces, `faces`) back to zero: every raster field is then zero.
  void clear_raster(bool faces);
  /// Counts, on the device, the non-finite values of every checked array (into step_sums_).
  void count_nonfinite(bool on_entry);
  /// The state the next step receives may hold values no step's check has seen: set by every
  /// method that changes the checked arrays from outside the stages (and by the tests' access),
  /// cleared by a step's own count at its end. Where it is clear, that count already covers what
  /// the step receives, and the step's entry count is not made again.
  bool entry_check_ = true;
  /// Zeroes (fields) or removes (particles) what the step record's counts show non-finite;
  /// true when there was any.
  bool contain_nonfinite(const int64_t* counts);
  /// Whether the step record's counts show any non-finite value.
  static bool nonfinite_found(const int64_t* counts) {
    return std::any_of(counts, counts + 2 * kCheckedArrays, [](int64_t c) { return c != 0; });
  }
  /// Every array of the live state the containment checks (device pointer, floats): the paint
  /// fields, 3 velocities, 5 load fields, then kNonfiniteParticleArrays particle fields.
  static constexpr size_t kNonfiniteParticleArrays = 8;
  static constexpr size_t kCheckedArrays = kPaintFieldCount + 3 + 5 + kNonfiniteParticleArrays;
  std::array<std::pair<float*, int64_t>, kCheckedArrays> checked_arrays();
  void clamp_particles_to_canvas();
  /// Files the brush's samples (at x - v rewind_dt) in sample_grid_ for queries of `range` from the
  /// particles: the window's columns and the canvas's depth.
  void build_sample_grid(float range, float rewind_dt);
  TransferEnv transfer_env();
  /// The ground per column of the window as it is now (TransferEnv::surface).
  const float* paint_surface();
  /// D0 of §5.2 for this step, limited so that the particle zone fits in the window's kept box
  /// around the samples (transfer_env; set by place_window).
  float effective_D0() const { return zone_D0_; }
  /// Horizontal box of the samples below the window's top: x_lo, x_hi, y_lo, y_hi; also sets
  /// ground_ for the next step. One read for both (outside a step; a step's box comes with its
  /// record).
  std::array<float, 4> samples_box();
  /// The samples' box maxima (x, -x, y, -y) and the ground under the footprint into out[0..5),
  /// on the device.
  static constexpr int kExtentValues = 5;
  void queue_samples_box(float* out);
  /// The box of queue_samples_box's values (the tips' point where no sample is below the
  /// window's top); sets ground_.
  std::array<float, 4> box_from(const float m[kExtentValues]);
  /// Where the window goes for the samples' box over the step (place_window), and the room it
  /// leaves, cells.
  struct WindowPlace {
    Int3 origin;
    float rim_room;   ///< between the box and the window's rim, less half a snap (the centre's error)
    float zone_room;  ///< for the particle zone at D0's floor (negative: the window cuts it)
    FlowColumns flow;  ///< the columns where paint flows: centred on the box, whatever the snap
    bool resting = false;  ///< the box stood still over the step: no wall moves, the window may slide
    bool free = false;     ///< the brush rests clear of the window: it goes where the paint runs
  };
  /// The window for the samples' box over the step (the union of `before` and `after`), and the
  /// D0 that keeps the particle zone inside its kept box (zone_D0_). `clear`: no sample below the
  /// window's top and the brush not coming down (a lifted brush need not be in it).
  WindowPlace place_window(const std::array<float, 4>& before, const std::array<float, 4>& after, bool clear = false);
  /// How many parts of a step keep each part's sweep of the brush inside the window (step()).
  int parts_of_step(const BrushPose* poses, int substeps) const;
  /// One part of a step: step() in full for the poses' sub-steps.
  void step_part(const BrushPose* pen_poses, int substeps, float dt);

  SimConfig config_;
  Profiler profiler_;
  Workspace ws_;
  SimCounters counters_;
  std::unique_ptr<TileStore> canvas_;
  std::unique_ptr<Brush> brush_;
  std::unique_ptr<Grid> grid_;
  ParticleStore particles_;
  SampleGrid sample_grid_;
  std::unique_ptr<BristleLoad> load_;
  std::unique_ptr<Transfer> transfer_;
  PaintBooks books_;
  // Window-sized scratch, allocated once: bristle psi and velocity, the grid's cell velocity
  // for the drag, the particles' raster (mass, face momentum and weight) and their density.
  DeviceBuffer<float> psi_, bristle_v_[3];
  DeviceBuffer<FloatPair> raster_cell_, raster_face_[3];  ///< the particles' raster (flip_kernels.h)
  /// The cells and faces the raster reached: zero elsewhere, and cleared through these.
  TouchListBuffers raster_cells_, raster_faces_[3];
  TouchListBuffers bristle_cells_;  ///< the cells of psi_ and bristle_v_ the bristles' raster reached
  DeviceBuffer<float> raster_density_, raster_oil_;  ///< its mass and oil per cell mass
  DeviceBuffer<float> overlay_mass_;
  /// The step's record on the device: the transfer's sums, the census's, the non-finite
  /// counts of every checked array (at the end, then on entry), the brush's rolled-back
  /// sub-steps (Brush::rollback_counter) and the canvas's and window's mass sums, read in one copy.
  struct StepSums {
    TransferSums transfer;
    double bristles, particles, window_density;
    int64_t nonfinite[2 * kCheckedArrays];
    int64_t brush_rollbacks;
    double canvas_sums[2];  ///< the canvas's scatter sums not yet read (TileStore::mass_sums)
    double gathered;        ///< the window region's density at its last gather
    float extent[kExtentValues];  ///< the samples' box and the ground at the step's end (queue_samples_box)
    float running[4];             ///< the box of running paint, on a resting step (Grid::running_box_into)
    int32_t tiles_used;           ///< the canvas's slots in use (TileStore::tiles_used)
    GridRecord grid;              ///< the grid's plan and solve figures (Grid::take_record)
    double load_change;           ///< kg the brush's paint gained from outside (BristleLoad's sink)
  };
  DeviceBuffer<StepSums> step_sums_;
  StepSums last_record_{};            ///< the last read of step_sums_
  DeviceBuffer<float> solid_height_;  ///< dried-paint top per window column (particles' solid, Eq. 8)
  DeviceBuffer<float> wet_top_;       ///< wet-paint surface per window column (free particles land on it)
  DeviceBuffer<float> surface_;       ///< the ground per window column (paint_surface)
  int64_t raster_step_ = -2;          ///< step (counters_.steps) raster_density_ was last made in
  float last_dt_ = 0.f;               ///< the last step's length, s
  Int3 raster_origin_{};              ///< and the window origin it was made at
  DeviceBuffer<float> extent_scratch_, extent_;  ///< the samples' box and the ground (samples_box)
  std::array<float, 4> box_{};                   ///< the samples' box at the end of the last step
  bool box_clear_ = false;  ///< no sample was below the window's top then (box_ is the tips' point)
  /// The box (x_lo, x_hi, y_lo, y_hi) of the paint that ran at the end of the last step, measured
  /// where the brush rested (place_window slides the window away from a wall it nears).
  std::optional<std::array<float, 4>> running_;
  /// How far the window of the resting brush has slid off its box's centre (x, y), cells.
  std::array<float, 2> slid_{};
  std::array<float, 4> guess_{};                 ///< this step's box as the pen's travel moves the last
  float box_miss_ = 0.f;                         ///< the last step's largest miss of guess_, cells
  /// Top of the dried paint under the brush's footprint at the end of the last step, cells: the
  /// pen's pressure presses the brush into the surface it meets, not below the bare canvas.
  float ground_ = 0.f;
  std::vector<BrushPose> lifted_;                ///< this step's poses raised by ground_
  float zone_D0_ = 0.f;
};

}  // namespace wb
