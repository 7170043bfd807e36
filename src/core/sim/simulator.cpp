#include "core/sim/simulator.h"

#include "core/color/ryb.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/exec/algorithms.h"
#include "core/exec/memory.h"
#include "core/io/undo_tiles.h"
#include "core/sim/memory_plan.h"
#include "core/particles/particles.h"
#include "core/sim/joint_fields.h"

namespace wb {
namespace {
/// The bound of the distance field's error, cells: ±block·√3 (docs/TRANSFER.md "Distance to the
/// bristles"), which every margin kept for D0 allows for.
float distance_error(const TransferParams& tp) { return float(tp.distance_block) * std::sqrt(3.f); }

/// Rim of the window, cells, where paint is always grid paint (transfer_env): wider than a
/// particle moving with a fast stroke (480 cells/s) travels in one 1/60 s step, so that one
/// leaving the window is caught in the rim rather than clamped to the wall.
constexpr int kKeepRim = 8;
/// Rim under the window's lid, cells: paint rises slowly, the kernel of Eq. 16 needs 3.
constexpr int kKeepRimTop = 3;
/// A samples' box whose centre moved less than this over a step (cells) is a brush at rest: a
/// lifted brush's bristles sway by 0.01-0.1 cells a step; the slowest stroke tested, 5 mm/s, moves 0.42.
constexpr float kRestingBox = 0.1f;
/// Wet paint with a face across the canvas faster than this (cells/s, 2 mm/s) runs, and the window
/// of a brush at rest slides away from a wall it nears (place_window). A bead of oily paint
/// (oil 0.9) runs down an upright canvas at about 80, stiff-and-oily's pool spreads its edge
/// faster than 10; a stiff bead at rest stays below 0.03, and a stroke's body settling behind the
/// lifted brush (the rib test's flat at 5 mm/s) runs between 3 and 10.
constexpr float kRunningPaint = 10.f;
/// An empty keep box: every particle goes to the grid (settle, grid-only paint).
KeepBox nowhere() { return KeepBox::of(Int3{}, Int3{}); }

/// Where the bristles meet the canvas: the rest tip under the handle (the ground's disc).
Vec3 footprint_centre(const BrushPose& pose, float length) {
  return pose.position + pose.rotation * Vec3(0.f, 0.f, -length);
}

MacView mac_view(const float* u, const float* v, const float* w, const ActiveWindow& win) {
  const Int3 n = win.dims(), o = win.origin();
  return MacView{u, v, w, n.x, n.y, n.z, o.x, o.y, o.z};
}

}  // namespace

Simulator::Simulator(const SimConfig& config, const BrushPose& initial_pose)
    : config_(config), profiler_(config.device), ws_(config.device) {
  const Device& d = config_.device;
  d.activate();
  // One gravity for the paint, the particles and the bristles: the grid's, tilted with the canvas.
  config_.params.particles.gravity = config_.params.grid.gravity_vector();
  // A run too large for the machine or the budget is refused here, before its first large
  // allocation; the particle store may grow into what the rest leaves.
  const int64_t particle_limit = check_memory(plan_memory(config_), config_, config_.params.particles.max_particles);
  canvas_ = std::make_unique<TileStore>(d, config_.canvas);
  brush_ = std::make_unique<Brush>(d, config_.brush, initial_pose, config_.params.brush_solver);
  grid_ = std::make_unique<Grid>(*canvas_, config_.params.grid, config_.window, Int3{});
  particles_ = ParticleStore(d, particle_limit);
  sample_grid_ = SampleGrid(d);
  // This brush's bristles hold in proportion to their volume (Eq. 12's M_max).
  const TransferParams tp = config_.params.transfer.for_bristle_radius(config_.brush.bristle_radius);
  load_ = std::make_unique<BristleLoad>(d, brush_->sample_count(), tp);
  std::vector<float> exchange = dip_exposure(brush_->layout(), config_.brush.samples_per_bristle,
                                             tp.dip_depth * config_.brush.length);
  for (float& x : exchange) x *= tp.dip_exchange;
  load_->set_dip_exchange(exchange);
  transfer_ = std::make_unique<Transfer>(d, tp);
  const GridDims g = grid_->dims();
  auto cells = [&](DeviceBuffer<float>& b) {
    b.set_device(d);
    b.resize(size_t(g.cells()));
    b.fill_zero();
  };
  cells(psi_);
  bristle_cells_.set_device(d);
  bristle_cells_.ensure(g.cells());  // with psi_ and bristle_v_ zero: nothing listed (Brush::rasterize)
  raster_cell_.set_device(d);
  raster_cell_.resize(size_t(g.cells()));
  raster_cell_.fill_zero();  // then kept zero beyond the listed cells (clear_raster)
  raster_cells_.set_device(d);
  raster_cells_.ensure(g.cells());
  cells(raster_oil_);
  cells(raster_density_);
  cells(overlay_mass_);
  for (auto* b : {&solid_height_, &wet_top_, &surface_}) {
    b->set_device(d);
    b->resize(size_t(g.nx) * size_t(g.ny));
  }
  for (auto* b : {&extent_scratch_, &extent_}) b->set_device(d);
  extent_.resize(5);
  box_ = samples_box();
  grid_->move_window(place_window(box_, box_).origin);
  step_sums_ = DeviceBuffer<StepSums>(d, 1);
  step_sums_.fill_zero();
  transfer_->set_sums(&step_sums_.data()->transfer);
  load_->set_change_sink(&step_sums_.data()->load_change);
  for (int c = 0; c < 3; ++c) {
    cells(bristle_v_[c]);
    raster_face_[c].set_device(d);
    raster_face_[c].resize(size_t(g.faces(c)));
    raster_face_[c].fill_zero();
    raster_faces_[c].set_device(d);
    raster_faces_[c].ensure(g.faces(c));
  }
  books_.open(census());
}

void Simulator::reset_brush(const BrushPose& pose) {
  BrushPose p = pose;
  p.position.z += ground_;
  brush_->reset(p);
  box_ = samples_box();  // the next step's window holds where the brush is now, not the path to it
  running_.reset();
  slid_ = {0.f, 0.f};
}

bool Simulator::paint_at_rest() const {
  const Grid& g = *grid_;
  // advect_courant: the largest outflow of a painted cell's face over the step, cells.
  return counters_.steps > 0 && g.stats().advect_courant <= g.params().rest_speed * last_dt_;
}

void Simulator::rest(double seconds, const BrushPose& pose) {
  WB_REQUIRE(std::isfinite(seconds) && seconds >= 0.0, "Simulator::rest: seconds must be finite and >= 0");
  settle();
  grid_->dry(float(seconds));
  reset_brush(pose);
  ++counters_.rests;
  counters_.rest_seconds += seconds;
}

PaintCensus Simulator::census() {
  return PaintBooks::census(*load_, particles_, grid_->window().total_mass(ws_), transfer_->params(), ws_);
}

PaintCensus Simulator::record_census(TransferRecord& rec, bool step_end) {
  // The census's sums join the transfer's and the non-finite counts on the device; one copy
  // brings the step's record. Where the counts show non-finite values, they are contained and
  // the census taken again (a second read, on that path alone).
  StepSums h{};
  for (int take = 0; take < 2; ++take) {
    StepSums* d = step_sums_.data();
    reduce_sum_into(device(), load_->m.data(), load_->size(), &d->bristles, ws_);
    reduce_sum_into(device(), particles_.m.data(), particles_.size(), &d->particles, ws_);
    const PaintWindow& paint = grid_->window().paint();
    reduce_sum_into(device(), paint.density.data(), paint.cell_count(), &d->window_density, ws_);
    mem::copy_on_device(device(), &d->brush_rollbacks, brush_->rollback_counter(), sizeof(int64_t));
    ActiveWindow& win = grid_->window();
    mem::copy_on_device(device(), d->canvas_sums, canvas_->mass_sums(), 2 * sizeof(double));
    mem::copy_on_device(device(), &d->gathered, win.gathered_sum(), sizeof(double));
    mem::copy_on_device(device(), &d->tiles_used, canvas_->tiles_used(), sizeof(int32_t));
    grid_->record_into(&d->grid);
    StepSums r{};
    step_sums_.copy_to_host(&r, 1);
    step_sums_.fill_zero();
    canvas_->take_tiles_used(r.tiles_used);
    grid_->take_record(r.grid);
    canvas_->take_mass_sums(r.canvas_sums);
    win.set_gathered_mass(r.gathered);
    if (take == 0) {
      // The transfer's scan ends came with the record: the store is compacted and the new
      // particles made now (none where something went non-finite: their paint stays put).
      if (step_end) transfer_->finish(r.transfer, !nonfinite_found(r.nonfinite), rec);
      books_.external(r.load_change);
      h = r;
      last_record_ = r;
      // Sub-steps the brush rolled back on the device (Brush::step) are non-finite events too.
      counters_.nonfinite_events += r.brush_rollbacks - brush_->rollbacks();
      brush_->rolled_back(r.brush_rollbacks);
    }
    h.bristles = r.bristles, h.particles = r.particles, h.window_density = r.window_density;
    if (take == 1 || !contain_nonfinite(h.nonfinite)) break;
  }
  Transfer::add_sums(h.transfer, double(transfer_->params().cell_mass()), rec);
  PaintCensus c;
  c.bristles = h.bristles;
  c.particles = h.particles;
  c.grid = grid_->window().total_mass_with(h.window_density) * double(transfer_->params().cell_mass());
  return c;
}

// The brush's paint changes from outside the transfers: the kg it gains or loses come back with
// the next step record, which enters them in the books (record_census).
void Simulator::load_paint(const PaintLoad& paint) {
  entry_check_ = true;
  load_->fill(paint);
}
void Simulator::dip(const PaintLoad& paint) {
  entry_check_ = true;
  load_->dip(paint);
}
void Simulator::wipe(float fraction) {
  entry_check_ = true;
  load_->wipe(fraction);
}
void Simulator::clean() {
  entry_check_ = true;
  load_->clean();
}

void Simulator::apply(const StrokeEvent& e) {
  switch (e.kind) {
    case StrokeEventKind::Dip: {
      PaintLoad well;
      for (int c = 0; c < 3; ++c) well.ryb[c] = e.ryb[c];
      well.oil = e.oil;
      well.load = e.load;
      dip(well);
      break;
    }
    case StrokeEventKind::Wipe: wipe(e.fraction); break;
    case StrokeEventKind::Clean: clean(); break;
    case StrokeEventKind::Dry: dry_canvas(); break;
  }
}

void Simulator::dry_canvas() {
  entry_check_ = true;
  settle();
  canvas_->dry_all();
  grid_->window().reload();
}

void Simulator::settle() {
  entry_check_ = true;
  if (particles_.size() > 0) {
    // Every particle, slow or not and near the bristles or not, goes back by Eq. 16: none may
    // stay anywhere.
    TransferEnv env = transfer_env();
    env.keep = nowhere();
    env.D0 = 0.f;
    SampleView none = brush_->samples();
    none.bristles = 0;  // no bristles: every particle is far from them
    TransferRecord rec;
    transfer_->update_distance(none, env);
    transfer_->particles_to_grid(particles_, env);
    particles_.compact(ws_);
    books_.record(rec, record_census(rec, false));
  }
  grid_->window().flush();
}

void Simulator::flush_window() { grid_->window().flush(); }

namespace {

/// Every particle field (state and scratch) on the host, for an exact restore.
struct ParticleCopy {
  int64_t count = 0;
#define WB_X(type, name, doc) std::vector<type> name;
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
};

ParticleCopy copy_particles(const ParticleStore& p) {
  ParticleCopy c;
  c.count = p.size();
#define WB_X(type, name, doc)      \
  c.name.resize(size_t(c.count)); \
  p.name.copy_to_host(c.name.data(), size_t(c.count));
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
  return c;
}

void restore_particles(ParticleStore& p, const ParticleCopy& c) {
  p.clear();
  p.append_uninitialised(c.count);
#define WB_X(type, name, doc) p.name.copy_range_from_host(c.name.data(), 0, size_t(c.count));
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
}

/// False for a tile that is all zero (as an undo writes back a tile that was never allocated).
bool tile_has_paint(const TileData& t) {
  const auto nonzero = [](const auto& v) { return std::any_of(v.begin(), v.end(), [](auto x) { return x != 0; }); };
  return nonzero(t.density) || nonzero(t.pigment_r) || nonzero(t.pigment_y) || nonzero(t.pigment_b) ||
         nonzero(t.oil) || nonzero(t.dryness);
}

}  // namespace

void Simulator::with_settled_canvas(const std::function<void(TileStore&)>& fn) {
  entry_check_ = true;
  ActiveWindow& win = grid_->window();
  PaintWindow& w = win.paint();
  TileStore& canvas = *canvas_;
  if (particles_.size() == 0) {  // nothing in flight: the flushed window is the settled canvas
    flush_window();
    fn(canvas);
    return;
  }
  // settle() changes the window, the particles and the tiles under the window (its books entry
  // closes: paint only moves from the particles to the grid).
  const std::vector<std::vector<float>> window = w.to_host();
  const double gathered = win.gathered_mass();
  const ParticleCopy particles = copy_particles(particles_);
  const Int3 o = w.origin(), n = w.dims();
  const std::vector<TileSnapshot> tiles = snapshot_tiles(canvas, tile_ids_in_rect(canvas, o.x, o.y, o.x + n.x, o.y + n.y));
  const auto restore = [&] {
    win.restore(window, gathered);
    restore_particles(particles_, particles);
    for (const TileSnapshot& t : tiles) restore_tile(canvas, t);
  };
  try {
    settle();
    fn(canvas);
  } catch (...) {
    restore();
    throw;
  }
  restore();
}

void Simulator::mark_brush_contacts(int32_t* trace, int w, int h, int ox, int oy, double* count, float* stretch) {
  brush_->mark_contacts_into(trace, w, h, ox, oy, 1.0f, solid_field(), count);
  brush_->max_stretch_into(stretch);
}

TileStore Simulator::settled_canvas_copy(const Device& device) {
  TileStore copy(device, canvas_->dims());
  with_settled_canvas([&](TileStore& c) {
    for (int id : c.allocated_tile_ids()) {
      TileData t = c.read_tile(id);
      if (tile_has_paint(t)) copy.write_tile(t);
    }
  });
  return copy;
}

BristleLoadHost Simulator::brush_paint() const { return load_->to_host(); }

void Simulator::set_brush_paint(const BristleLoadHost& paint) {
  entry_check_ = true;
  const double before = load_->total_mass(ws_);
  load_->from_host(paint);
  books_.external(load_->total_mass(ws_) - before);
}

PaintLoad Simulator::brush_mean_paint(const PaintLoad& clean) { return load_->mean_paint(ws_, clean); }

void Simulator::lay_ground(const CanvasGround& ground, Vec3 primer_ryb) {
  if (ground.weave == Weave::Smooth) return;
  const CanvasDims& d = config_.canvas;
  const std::string why = ground_refusal(ground, d.width, d.height, d.depth, config_.params.grid.cell_size);
  WB_REQUIRE(why.empty(), why);
  // Every tile of the canvas is allocated: refused at once where the room is short, and the
  // particle store's share shrinks by what the ground takes.
  const int64_t need = ground_bytes(d);
  const size_t room = mem::room(device());
  if (size_t(need) > room)
    WB_THROW("a canvas ground allocates the whole " + std::to_string(d.width) + " x " + std::to_string(d.height) +
             " x " + std::to_string(d.depth) + " canvas: " + mem::format_bytes(double(need)) + ", and " +
             mem::format_bytes(double(room)) + " is left (the machine's available memory or --memory-limit): " +
             "paint on a smaller canvas or without a ground");
  const int64_t per = plan_memory(config_).per_particle;
  particles_.set_limit(std::max({int64_t(1), particles_.size(), particles_.limit() - need / per}));
  const WeaveField w = weave_field(ground, config_.params.grid.cell_size, primer_ryb);
  replace_canvas([&](TileStore& canvas) { canvas.lay_weave(w); });
}

void Simulator::replace_canvas(const std::function<void(TileStore&)>& write) {
  entry_check_ = true;
  const double before = census().total();
  flush_window();  // `write` sees the live canvas
  write(*canvas_);
  grid_->window().reload();
  particles_.clear();
  books_.external(census().total() - before);
}

std::array<float, 4> Simulator::samples_box() {
  queue_samples_box(extent_.data());
  float m[kExtentValues];
  extent_.copy_to_host(m, kExtentValues);
  return box_from(m);
}

void Simulator::queue_samples_box(float* out) {
  const SampleView s = brush_->samples();
  const int64_t n = s.count();
  ActiveWindow& win = grid_->window();
  const Int3 o = win.origin(), wn = win.dims();
  const int64_t columns = int64_t(wn.x) * wn.y;
  if (extent_scratch_.size() < size_t(std::max(4 * n, columns))) extent_scratch_.resize(size_t(std::max(4 * n, columns)));
  // No sample below the top (or none at all) leaves -inf maxima: box_from takes the tips' point.
  joint_sample_extent(device(), s.x, n, float(o.z + wn.z), extent_scratch_.data());
  for (int c = 0; c < 4; ++c) reduce_max_into(device(), extent_scratch_.data() + c * n, n, out + c, ws_);
  // The ground for the next step: the dried paint's top under the footprint (the disc of the
  // brush's half width around where its tips meet the canvas).
  const ParticleParams& pp = config_.params.particles;
  const Vec3 tip = footprint_centre(brush_->pose(), config_.brush.length);
  joint_ground_under(device(), win.paint().view(), config_.params.grid.dry_threshold, tip.x, tip.y,
                     0.5f * std::max(config_.brush.width, config_.brush.thickness), pp.floor_z, extent_scratch_.data());
  reduce_max_into(device(), extent_scratch_.data(), columns, out + 4, ws_);
}

std::array<float, 4> Simulator::box_from(const float m[kExtentValues]) {
  ground_ = std::isfinite(m[4]) ? std::max(m[4], 0.f) : 0.f;
  const Vec3 tip = footprint_centre(brush_->pose(), config_.brush.length);
  box_clear_ = !(m[0] >= -m[1] && m[2] >= -m[3]);
  if (box_clear_) return {tip.x, tip.x, tip.y, tip.y};  // none below the top: the tips' point
  return {-m[1], m[0], -m[3], m[2]};
}

Simulator::WindowPlace Simulator::place_window(const std::array<float, 4>& before, const std::array<float, 4>& after,
                                               bool clear) {
  // The window holds the samples' box over the step (the swept contact lays paint from where
  // each sample was to where it is), centred on it. The particle zone must end inside the kept
  // box: a zone cut by it returns its particles in a strip at every move of the window, a band
  // across the stroke at the snap's period, instead of by Eq. 16 behind the brush
  // (docs/TRANSFER.md "The particle zone"). The zone reaches D0 + return_margin from the samples,
  // plus the distance blocks' error, and the window's centre is off the box's by up to half a
  // snap. D0 keeps a floor, the absorption's reach through the block distance: without
  // particles around the bristles the brush could pick up no paint (Eq. 14, 15). A brush too
  // large for its window at that floor needs a larger window (`simulation.window`).
  const float x0 = std::min(before[0], after[0]), x1 = std::max(before[1], after[1]);
  const float y0 = std::min(before[2], after[2]), y1 = std::max(before[3], after[3]);
  const Int3 n = grid_->window().dims();
  const TransferParams& tp = config_.params.transfer;
  WindowPlace w;
  w.rim_room = 0.5f * std::min(float(n.x) - (x1 - x0), float(n.y) - (y1 - y0)) - float(kKeepRim) -
               0.5f * float(config_.params.grid.window_snap);
  const float room = w.rim_room - tp.return_margin - distance_error(tp);  // the zone's D0 fits in it
  const float D0 = config_.params.particles.D0;
  const float floor_D0 = std::min(D0, transfer_->params().absorb_range() + distance_error(tp));
  zone_D0_ = std::clamp(room, floor_D0, D0);
  w.zone_room = room - floor_D0;
  float cx = 0.5f * (x0 + x1), cy = 0.5f * (y0 + y1);
  const int snap = std::max(config_.params.grid.window_snap, 1);
  const float moved = std::max(std::abs(after[0] + after[1] - before[0] - before[1]),
                               std::abs(after[2] + after[3] - before[2] - before[3]));
  w.resting = 0.5f * moved <= kRestingBox;
  w.free = w.resting && clear;
  if (!w.resting) slid_ = {0.f, 0.f};
  if (w.resting) {
    // Paint flows only inside the window. A brush at rest leaves the window free to slide off its
    // box's centre toward paint that ran at the last step's end within the rim of a wall of the
    // window centred on the box (drips down an easel, an oily pool spreading): along each axis,
    // far enough to give that paint a rim's room beyond the rim, as far as the paint at the other
    // wall keeps out of its own rim and the particle zone at D0's floor and the box's miss allow.
    // The window stays slid while the brush rests (a window swinging back and forth would stop
    // and free the paint at its walls by turns). A wall that slid back over a stroke's body would
    // set its frozen part flowing again, a step where the freeze resumed: paint settling runs
    // slower than kRunningPaint, and paint away from the walls moves no wall.
    // A brush lifted clear of the window (the easel's painter holding it up beside the work) has
    // nothing there to hold: the window goes as far as the running paint asks, and comes back to
    // the brush the step it starts down.
    const float slack = w.free ? std::numeric_limits<float>::infinity()
                               : std::max(0.f, std::min(w.zone_room, w.rim_room - 2.f * box_miss_ - 1.f));
    if (running_) {
      const std::array<float, 4>& m = *running_;
      const Int3 o = grid_->window().origin_for(Vec3(cx, cy, 0.f), snap);
      const auto slide = [&](float mlo, float mhi, int wall, int side, float was) {
        const float lo = float(wall + kKeepRim) - mlo, hi = mhi - float(wall + side - kKeepRim);  // > 0: in the rim
        float d = 0.f;
        if (lo > 0.f && hi < 0.f) d = -std::min(lo + float(kKeepRim), -hi);
        if (hi > 0.f && lo < 0.f) d = std::min(hi + float(kKeepRim), -lo);
        return std::abs(was) > std::abs(d) && was * d >= 0.f ? was : d;
      };
      slid_ = {slide(m[0], m[1], o.x, n.x, slid_[0]), slide(m[2], m[3], o.y, n.y, slid_[1])};
    }
    const float dx = std::clamp(slid_[0], -slack, slack), dy = std::clamp(slid_[1], -slack, slack);
    const float off = std::max(std::abs(dx), std::abs(dy));
    cx += dx, cy += dy;
    if (!w.free) w.rim_room -= off, w.zone_room -= off;  // a free window holds neither the box nor its zone
    zone_D0_ = std::clamp(room - off, floor_D0, D0);
  }
  w.origin = grid_->window().origin_for(Vec3(cx, cy, 0.f), snap);
  // Paint flows in the columns whose centres lie within the window's half-size less half a snap
  // of the box's centre: always inside the window (its origin is off by at most half a snap),
  // and moving with the brush cell by cell. Paint a window wall leaves behind stops where it
  // is; were the walls the limit, each move of a snap would stop at once a strip of paint laid
  // over a snap of the brush's travel, still settling, and the body would set in steps of the
  // snap's length (docs/GRID.md "The window's walls"). A brush at rest moves no wall: the whole
  // window flows.
  if (!w.resting) {
    const float hx = 0.5f * float(n.x - snap), hy = 0.5f * float(n.y - snap);
    w.flow = FlowColumns{int(std::ceil(cx - hx - 0.5f)), int(std::ceil(cx + hx - 0.5f)), int(std::ceil(cy - hy - 0.5f)),
                         int(std::ceil(cy + hy - 0.5f))};
  }
  return w;
}

const float* Simulator::paint_surface() {
  // The particles' raster of this step or the last, where the window has not moved since: near
  // the bristles the paint is mostly particles (§5.2), and its grid part alone reads as air.
  ActiveWindow& win = grid_->window();
  const Int3 o = win.origin();
  const bool raster = raster_step_ >= counters_.steps - 1 && o.x == raster_origin_.x && o.y == raster_origin_.y &&
                      o.z == raster_origin_.z;
  particles_ground_surface(device(), win.paint().view(), raster ? raster_density_.data() : nullptr,
                           config_.params.grid.dry_threshold, config_.params.grid.liquid_threshold,
                           config_.params.particles.floor_z, surface_.data());
  return surface_.data();
}

TransferEnv Simulator::transfer_env() {
  ActiveWindow& win = grid_->window();
  TransferEnv env;
  env.paint = win.paint().view();
  env.psi = psi_.data();
  env.velocity = mac_view(win.velocity(0).data(), win.velocity(1).data(), win.velocity(2).data(), win);
  env.floor_z = config_.params.particles.floor_z;
  env.dry_threshold = config_.params.grid.dry_threshold;
  env.D0 = config_.particles ? effective_D0() : 0.f;
  env.lattice_anchor = brush_->pose().position;
  env.surface = paint_surface();
  // Particles live inside the window less a rim of kKeepRim cells (beyond the reach of Eq. 16's
  // kernel): one that enters the rim goes to the grid, and rim paint is never sampled into
  // particles, so nothing cycles between the two there (docs/TRANSFER.md).
  const Int3 n = win.dims();
  env.keep = KeepBox::of(Int3{kKeepRim, kKeepRim, 0}, Int3{n.x - kKeepRim, n.y - kKeepRim, n.z - kKeepRimTop});
  // Grid-only paint (Fig. 7a/c): particles may live nowhere, so what the bristles emit goes to
  // the grid on the next step and no cell is sampled into particles.
  if (!config_.particles) env.keep = nowhere();
  return env;
}

BrushPicture Simulator::brush_picture() const {
  BrushPicture b;
  b.bristles = brush_->bristles();
  b.vertices_per_bristle = brush_->vertices_per_bristle();
  const Vec3 ferrule = brush_->pose().position;
  b.vertices = brush_->vertices_to_host();
  for (Vec3& v : b.vertices) v -= ferrule;
  b.canvas_z = -ferrule.z;
  const std::vector<float> m = load_->m.to_host(), cap = load_->potential.to_host(), r = load_->pigment_r.to_host(),
                           y = load_->pigment_y.to_host(), bl = load_->pigment_b.to_host();
  const int64_t per = brush_->spec().samples_per_bristle;
  b.ryb.assign(size_t(b.bristles), Vec3{});
  b.fill.assign(size_t(b.bristles), 0.f);
  // Colours mix by mass as Algorithm 2 mixes them (linear RYB, then the mean brightness).
  double mass = 0.0, capacity = 0.0, bright = 0.0;
  Vec3 sum{};
  for (int k = 0; k < b.bristles; ++k) {
    double mk = 0.0, ck = 0.0, bk = 0.0;
    Vec3 sk{};
    for (int64_t j = k * per; j < (k + 1) * per; ++j) {
      const Vec3 c(r[size_t(j)], y[size_t(j)], bl[size_t(j)]);
      mk += m[size_t(j)];
      ck += cap[size_t(j)];
      sk += c * m[size_t(j)];
      bk += double(pigment_brightness(c)) * m[size_t(j)];
    }
    if (mk > 0.0) b.ryb[size_t(k)] = rescale_to_brightness(sk / float(mk), float(bk / mk));
    b.fill[size_t(k)] = ck > 0.0 ? float(mk / ck) : 0.f;
    mass += mk;
    capacity += ck;
    bright += bk;
    sum += sk;
  }
  if (mass > 0.0) b.mean_ryb = rescale_to_brightness(sum / float(mass), float(bright / mass));
  b.amount = capacity > 0.0 ? float(mass / capacity) : 0.f;
  return b;
}

ParticleOverlay Simulator::particle_overlay() {
  ParticleOverlay o{};
  const int64_t n = particles_.size();
  if (overlay_mass_.size() < size_t(n)) overlay_mass_.grow_keep(size_t(n));
  // The renderer splats volume (cell fractions); particle mass is kg.
  if (n) joint_scale(device(), particles_.m.data(), overlay_mass_.data(), n, 1.f / transfer_->params().cell_mass());
  o.x = particles_.x.data();
  o.mass = overlay_mass_.data();
  o.r = particles_.pigment_r.data();
  o.y = particles_.pigment_y.data();
  o.b = particles_.pigment_b.data();
  o.oil = particles_.oil.data();
  o.n = n;
  o.origin = grid_->window().origin();
  o.dims = grid_->window().dims();
  return o;
}

int Simulator::parts_of_step(const BrushPose* poses, int substeps) const {
  // The swept contact lays paint from where each sample was to where it is, inside the window
  // (place_window centres it on the samples' box over the step). A sweep longer than the window
  // holds beside the brush would be laid in window-sized blocks with gaps where the window stood:
  // the step is cut into parts, each placing the window anew. The sweep is the pen's, known here
  // (the tips' point of each pose); the brush's own extent is the samples' box of the last step.
  const float L = config_.brush.length;
  Vec3 lo = footprint_centre(brush_->pose(), L), hi = lo;
  for (int i = 0; i < substeps; ++i) {
    const Vec3 c = footprint_centre(poses[i], L);
    lo = Vec3(std::min(lo.x, c.x), std::min(lo.y, c.y), 0.f), hi = Vec3(std::max(hi.x, c.x), std::max(hi.y, c.y), 0.f);
  }
  const float sweep = std::max(hi.x - lo.x, hi.y - lo.y);
  const Int3 n = grid_->window().dims();
  const float side = float(std::min(n.x, n.y));
  const float brush = std::max(box_[1] - box_[0], box_[3] - box_[2]);
  // The window is centred on the samples' box over the part within half a snap. A quarter of
  // the room is kept for the bristles' lag behind the pen, which changes most as a flick speeds
  // up; a brush too large for its window still moves a quarter window a part.
  const float fits = std::max(0.75f * (side - brush - float(config_.params.grid.window_snap)), 0.25f * side);
  return std::clamp(int(std::ceil(sweep / fits)), 1, substeps);
}

void Simulator::step(const BrushPose* pen_poses, int substeps, float dt) {
  WB_REQUIRE(substeps >= 1 && dt > 0.f && std::isfinite(dt), "Simulator::step: bad sub-step count or dt");
  const int parts = parts_of_step(pen_poses, substeps);
  if (parts > 1) ++counters_.split_steps, counters_.step_parts += parts;
  ++counters_.steps;
  counters_.substeps += substeps;
  // Sub-steps are even in time: each part takes its share of them and of dt.
  const int64_t cut = counters_.zone_cut_steps;
  for (int p = 0, first = 0; p < parts; ++p) {
    const int last = int((int64_t(substeps) * (p + 1)) / parts);
    step_part(pen_poses + first, last - first, dt * float(last - first) / float(substeps));
    first = last;
  }
  counters_.zone_cut_steps = cut + (counters_.zone_cut_steps > cut ? 1 : 0);  // steps, not parts
}

void Simulator::step_part(const BrushPose* pen_poses, int substeps, float dt) {
  // The pen's poses measure the brush from the bare canvas (pose_from_pen); the brush meets the
  // dried paint under it first, so they are raised by its top (docs/TRANSFER.md "Scumble").
  lifted_.assign(pen_poses, pen_poses + substeps);
  for (BrushPose& p : lifted_) p.position.z += ground_;
  const BrushPose* poses = lifted_.data();
  ProfilerGuard guard(&profiler_);
  WB_PROFILE_SCOPE("sim.step");
  grid_->set_particle_density(nullptr);  // last step's raster is stale
  if (entry_check_) count_nonfinite(true);

  // --- 1-2. Brush (§4.1) in sub-steps, then its samples ------------------------------------
  const std::array<float, 4> box_before = box_;
  const Vec3 tips_before = footprint_centre(brush_->pose(), config_.brush.length);
  brush_stage(poses, substeps, dt);
  bool resting = false;
  float zone_room = 1e30f;  // this part's room for the particle zone (WindowPlace::zone_room)
  float pen_slid = 0.f;     // the tips' travel over the part in the canvas plane, cells

  // --- 3. Window: follow the brush; rasterise the bristles into it (boundary of §4.2) -----
  {
    WB_PROFILE_SCOPE("window");
    // The samples' box at the step's end comes with the step's record. Here the last step's box
    // goes where the pen took the brush's tips, and the window and D0 are placed on it. Widened
    // by twice the last step's miss and a cell (the bristles' shape changes: a landing splays
    // them, a drag bends them back), the box over the step must stay out of the window's rim;
    // where it would not, the box is read instead (docs/TRANSFER.md "The particle zone").
    const Vec3 moved = footprint_centre(brush_->pose(), config_.brush.length) - tips_before;
    pen_slid = std::hypot(moved.x, moved.y);
    guess_ = {box_before[0] + moved.x, box_before[1] + moved.x, box_before[2] + moved.y, box_before[3] + moved.y};
    box_ = guess_;
    // A brush is clear of the window when no sample was below its top at the last step's end and
    // its tips are not coming down: only then may the window leave it (no particle clings to
    // bristles above the window, and those elsewhere go to the grid at the move as at any).
    const bool clear = box_clear_ && footprint_centre(brush_->pose(), config_.brush.length).z >= tips_before.z;
    WindowPlace w = place_window(box_before, box_, clear);
    if (!w.free && w.rim_room < 2.f * box_miss_ + 1.f) {
      box_ = samples_box();
      w = place_window(box_before, box_);
      ++counters_.box_reads;
    }
    resting = w.resting;
    zone_room = w.zone_room;
    if (particles_.size() > 0) deposit_leaving_particles(w.origin);
    grid_->move_window(w.origin);
    grid_->set_flow_columns(w.flow);
    brush_->rasterize(grid_->window().origin(), grid_->window().dims(), psi_.data(), bristle_v_[0].data(),
                      bristle_v_[1].data(), bristle_v_[2].data(), &bristle_cells_);
    grid_->set_bristles(BristleField{psi_.data(), bristle_v_[0].data(), bristle_v_[1].data(), bristle_v_[2].data()});
  }

  // --- 4. Particles (§4.3): nearest sample, two-step adhesion (Eq. 8-10) -------------------
  if (config_.particles) particle_stage(dt);

  // --- 5-6. Grid (§4.2) on the joint fields: advect, + particles, forces, viscosity,
  //          fixed-point projection (Alg. 1), drying ---------------------------------------
  {
    WB_PROFILE_SCOPE("grid");
    grid_->step(dt, [&] {
      if (config_.particles && particles_.size() > 0) joint_fields_stage();
    });
  }

  // --- 7. FLIP/PIC (Eq. 11): the grid keeps its velocity for the next step ---------------
  if (config_.particles && particles_.size() > 0) {
    WB_PROFILE_SCOPE("particles.flip");
    ActiveWindow& win = grid_->window();
    const MacView before = mac_view(grid_->velocity_before_solve(0).data(),
                                    grid_->velocity_before_solve(1).data(),
                                    grid_->velocity_before_solve(2).data(), win);
    const MacView after = mac_view(win.velocity(0).data(), win.velocity(1).data(), win.velocity(2).data(), win);
    particles_flip_pic(device(), particles_.view(), before, after, config_.params.particles.gamma);
  }

  // --- 8. Transfer (§5): bristle <-> particle, grid <-> particle ---------------------------
  TransferRecord rec;
  {
    WB_PROFILE_SCOPE("transfer");
    if (config_.particles) {
      // The absorption candidates are found against this step's samples, as far as the
      // largest load sphere reaches (Eq. 14 takes a particle only inside R_j) and, for the
      // touching samples' pick-up of the film, back along the path the brush slid this part
      // (docs/TRANSFER.md "Swept contact"), as far as the adhesion's query reaches (D1): the
      // query's work is then bounded by that one's, not by the pen's speed.
      const float range = transfer_->params().absorb_range() + std::min(pen_slid, config_.params.particles.D1);
      WB_PROFILE_SCOPE("transfer.nearest");
      build_sample_grid(range, 0.f);
      sample_grid_.query_nearest(particles_.view(), range);
    }
    TransferEnv env = transfer_env();
    env.dt = dt;  // wicking along the bristles over this step
    // The device's sums include the particles deposited before the window moved.
    rec = transfer_->step(brush_->samples(), *load_, particles_, env);
  }

  {
    // One read brings the step's record: the non-finite counts, the transfer's sums and the
    // census. Where something went non-finite, it is contained and the census taken again.
    WB_PROFILE_SCOPE("books");
    count_nonfinite(false);
    entry_check_ = false;
    queue_samples_box(step_sums_.data()->extent);
    if (resting) grid_->running_box_into(step_sums_.data()->running, kRunningPaint);
    books_.record(rec, record_census(rec, true));
    counters_.particles_refused += rec.emission_dropped + rec.to_particles_dropped;
    const float* m = last_record_.running;
    running_.reset();
    if (resting && m[0] >= -m[1] && m[2] >= -m[3]) running_ = std::array<float, 4>{-m[1], m[0], -m[3], m[2]};
    counters_.returned_at_moves += rec.to_grid_at_moves;
    // A cut zone counts where the window's move returned particles: the bands it lays. A lifted
    // brush travelling farther than the window holds cuts it on paper and returns nothing.
    if (config_.particles && zone_room < 0.f && rec.to_grid_at_moves > 0) {
      ++counters_.zone_cut_steps;
      counters_.zone_room_min = std::min(counters_.zone_room_min, zone_room);
    }
    box_ = box_from(last_record_.extent);
    box_miss_ = 0.f;
    for (int k = 0; k < 4; ++k) box_miss_ = std::max(box_miss_, std::abs(box_[k] - guess_[k]));
  }
  clamp_particles_to_canvas();
  last_dt_ = dt;
  counters_.particles_max = std::max(counters_.particles_max, particles_.size());
}

void Simulator::deposit_leaving_particles(Int3 next) {
  // Particles live only inside the window (they are rasterised into it and go back to the
  // grid through it). Those outside the part of the window that stays, less a margin for
  // the kernel of Eq. 16, return to the grid before the window moves.
  ActiveWindow& win = grid_->window();
  const Int3 cur = win.origin(), n = win.dims();
  if (next.x == cur.x && next.y == cur.y && next.z == cur.z) return;  // the step's own pass keeps the rim
  const int m = kKeepRim;
  TransferEnv env = transfer_env();  // z rim as in every step
  env.keep = KeepBox::of(Int3{std::max(cur.x, next.x) - cur.x + m, std::max(cur.y, next.y) - cur.y + m, 0},
                         Int3{std::min(cur.x, next.x) + n.x - cur.x - m, std::min(cur.y, next.y) + n.y - cur.y - m,
                              n.z - kKeepRimTop});
  env.only_leaving = true;
  // Those returned are left weightless in place (transfer_to_grid_mark): the step's transfer
  // compacts them away with its own, and its record counts them (returned_at_moves).
  transfer_->particles_to_grid(particles_, env);
}

SolidField Simulator::solid_field() {
  SolidField s;
  s.tiles = canvas_->view();
  s.dryness_threshold = config_.params.grid.dry_threshold;
  s.valid = !canvas_->no_tiles();  // an empty canvas has no dried paint
  return s;
}

void Simulator::brush_stage(const BrushPose* poses, int substeps, float dt) {
  ActiveWindow& win = grid_->window();
  // The grid velocity kept from the last step drags the bristles (Eq. 2's a_i, §4.3), read on
  // its faces where each bristle is.
  const Int3 n = win.dims(), o = win.origin();
  DragField drag{win.velocity(0).data(), win.velocity(1).data(), win.velocity(2).data(), win.paint().density.data(),
                 n.x, n.y, n.z, o.x, o.y, o.z, config_.params.bristle_drag};
  BrushEnvironment env;
  env.gravity = config_.params.particles.gravity;
  env.drag = config_.params.bristle_drag > 0.f ? &drag : nullptr;
  env.solid = solid_field();
  brush_->step(poses, substeps, dt, env);
}

void Simulator::particle_stage(float dt) {
  if (particles_.size() == 0) return;
  WB_PROFILE_SCOPE("particles");
  const ParticleParams& prm = config_.params.particles;
  // Neighbours in space as neighbours in memory: the raster sums the splats of each run of
  // particles in a half cell before its atomic adds, and every pass over the particles reads the
  // grid, the samples and the paint in order (docs/PARTICLES.md "Order").
  particles_.sort_by_cell(grid_->window().origin(), grid_->window().dims(), ws_);
  // Samples are at t + dt, particles at t: file the samples rewound to t (sample_grid.h). The
  // query reaches D1, the range of Eq. 10: beyond it no sample moves a particle.
  {
    WB_PROFILE_SCOPE("particles.nearest");
    build_sample_grid(prm.D1, dt);
    sample_grid_.query_nearest(particles_.view(), prm.D1);
  }
  // The particles rest on the canvas and on dried paint (d_k of Eq. 8 is measured to both), and
  // free ones land on the wet paint's surface. The wet paint is the joint paint, grid and
  // particles, as the grid's liquid test counts it: near the bristles most of a layer is
  // particles (§5.2), and its grid part alone would read as air that its particles fall through.
  ActiveWindow& win = grid_->window();
  const Int3 n = win.dims(), o = win.origin();
  clear_raster(true);
  ParticleRasterView rv{raster_cell_.data(), {}, n.x, n.y, n.z, o.x, o.y, o.z};
  rv.cell_list = raster_cells_.view();
  particles_rasterise(device(), particles_.view(), rv);
  joint_raster_density(device(), raster_cell_.data(), raster_density_.data(), nullptr, rv.cell_list,
                       int64_t(raster_cell_.size()), 1.f / transfer_->params().cell_mass());
  particles_solid_height(device(), win.paint().view(), raster_density_.data(), config_.params.grid.dry_threshold,
                         config_.params.grid.liquid_threshold, prm.floor_z, solid_height_.data(), wet_top_.data());
  SolidView solid;
  solid.floor_z = prm.floor_z;
  solid.height = solid_height_.data();
  solid.wet_top = wet_top_.data();
  solid.nx = win.dims().x;
  solid.ny = win.dims().y;
  solid.ox = win.origin().x;
  solid.oy = win.origin().y;
  const SampleView samples = brush_->samples();
  auto* motion = static_cast<SampleMotion*>(ws_.get(sizeof(SampleMotion) * size_t(samples.count())));
  particles_adhesion_step(device(), particles_.view(), samples, solid, prm, dt, motion);
  clamp_particles_to_canvas();
}

void Simulator::build_sample_grid(float range, float rewind_dt) {
  // Where the particles are: in the window's columns (one that enters its rim goes to the grid,
  // docs/TRANSFER.md "The particle zone"), at any height of the canvas (paint held by bristles
  // above the window's layers). The samples within `range` of that are all their queries can
  // find, and the grid's cells are bounded by it.
  const ActiveWindow& win = grid_->window();
  const Int3 o = win.origin(), n = win.dims();
  const Vec3 lo(float(o.x) - range, float(o.y) - range, -range);
  const Vec3 hi(float(o.x + n.x) + range, float(o.y + n.y) + range, float(config_.canvas.depth) + range);
  sample_grid_.build(brush_->samples(), config_.params.particles.sample_cell, lo, hi, ws_, rewind_dt);
}

void Simulator::clamp_particles_to_canvas() {
  if (particles_.size() == 0) return;
  const CanvasDims c = config_.canvas;
  // Half a cell inside the walls, so that Eq. 16's kernel lands on canvas cells.
  joint_clamp_to_canvas(device(), particles_.view(), Vec3(0.5f, 0.5f, config_.params.particles.floor_z),
                        Vec3(float(c.width) - 0.5f, float(c.height) - 0.5f, float(c.depth) - 0.5f));
}

void Simulator::joint_fields_stage() {
  WB_PROFILE_SCOPE("particles.rasterise");
  ActiveWindow& win = grid_->window();
  const Int3 n = win.dims(), o = win.origin();
  clear_raster(false);  // the particle stage's cells; its faces are clear
  ParticleRasterView rv{raster_cell_.data(),
                        {raster_face_[0].data(), raster_face_[1].data(), raster_face_[2].data()},
                        n.x, n.y, n.z, o.x, o.y, o.z};
  rv.cell_list = raster_cells_.view();
  for (int c = 0; c < 3; ++c) rv.face_list[c] = raster_faces_[c].view();
  particles_rasterise(device(), particles_.view(), rv);
  const float cell_mass = transfer_->params().cell_mass();
  // The particles' mass and oil in the density's units (the oil for the joint paint's
  // rheology, JointOil).
  joint_raster_density(device(), raster_cell_.data(), raster_density_.data(), raster_oil_.data(), rv.cell_list,
                       int64_t(raster_cell_.size()), 1.f / cell_mass);
  grid_->set_particle_density(raster_density_.data(), raster_oil_.data());
  raster_step_ = counters_.steps, raster_origin_ = o;
  joint_blend_velocity(device(), grid_->view(), win.paint().view(), rv, cell_mass);
}

void Simulator::clear_raster(bool faces) {
  // The raster's passes visit the cells and faces it reached (TouchList), not the window: what
  // they wrote goes back to zero through the same lists, after which each list is empty.
  joint_clear_raster(device(), raster_cells_.view(), raster_cells_.capacity(), raster_cell_.data(),
                     raster_density_.data(), raster_oil_.data());
  raster_cells_.clear_count();
  if (!faces) return;
  for (int c = 0; c < 3; ++c) {
    joint_clear_raster(device(), raster_faces_[c].view(), raster_faces_[c].capacity(), raster_face_[c].data(), nullptr,
                       nullptr);
    raster_faces_[c].clear_count();
  }
}

std::array<std::pair<float*, int64_t>, Simulator::kCheckedArrays> Simulator::checked_arrays() {
  // Grid fields, velocities and the brush's load first (zeroed where non-finite), then the
  // particles' fields (kNonfiniteParticleArrays; a particle with any non-finite field is removed).
  ActiveWindow& win = grid_->window();
  PaintWindow& paint = win.paint();
  const int64_t np = particles_.size(), ns = load_->size();
  return {{
#define WB_X(name, doc) {paint.name.data(), paint.cell_count()},
      WB_PAINT_FIELDS(WB_X)
#undef WB_X
      {win.velocity(0).data(), int64_t(win.velocity(0).size())},
      {win.velocity(1).data(), int64_t(win.velocity(1).size())},
      {win.velocity(2).data(), int64_t(win.velocity(2).size())},
      {load_->m.data(), ns},
      {load_->pigment_r.data(), ns},
      {load_->pigment_y.data(), ns},
      {load_->pigment_b.data(), ns},
      {load_->oil.data(), ns},
      {reinterpret_cast<float*>(particles_.x.data()), 3 * np},
      {reinterpret_cast<float*>(particles_.v.data()), 3 * np},
      {particles_.m.data(), np},
      {particles_.pigment_r.data(), np},
      {particles_.pigment_y.data(), np},
      {particles_.pigment_b.data(), np},
      {particles_.oil.data(), np},
      {particles_.dryness.data(), np}}};
}

void Simulator::count_nonfinite(bool on_entry) {
  // What the step receives is counted too (a value that went bad between steps, from outside
  // the step's stages): the step's own clamps may absorb it silently (max(m, 0) of NaN is 0),
  // so this is where it is seen. Counted on the device; read with the step's record.
  FloatArrays all;
  for (const auto& [ptr, n] : checked_arrays()) all.add(ptr, n);
  count_nonfinite_each_into(device(), all, step_sums_.data()->nonfinite + (on_entry ? kCheckedArrays : 0), ws_);
}

bool Simulator::contain_nonfinite(const int64_t* counts) {
  // A non-finite value anywhere in the live state is zeroed (grid fields, velocities, the
  // brush's load: that paint is lost and the books show it) or removed (particles) before
  // anything renders or scatters it; the event is counted.
  if (!nonfinite_found(counts)) return false;
  const auto arrays = checked_arrays();
  const size_t n = arrays.size();
  for (size_t i = 0; i + kNonfiniteParticleArrays < n; ++i)
    if (counts[i]) joint_zero_nonfinite(device(), arrays[i].first, arrays[i].second);
  int64_t particles_bad = 0;
  for (size_t i = n - kNonfiniteParticleArrays; i < n; ++i) particles_bad += counts[i];
  if (particles_bad) {
    joint_kill_nonfinite(device(), particles_.view());
    particles_.compact(ws_);
  }
  ++counters_.nonfinite_events;
  return true;
}

}  // namespace wb
