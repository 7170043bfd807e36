#include "core/session/session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/color/ryb.h"
#include "core/exec/error.h"
#include "core/io/brush_json.h"

namespace wb {

void put_paint_dab(TileStore& canvas, float cx, float cy, float radius, float height, const PaintLoad& paint) {
  const CanvasDims d = canvas.dims();
  const int x0 = std::max(0, int(std::floor(cx - radius))), x1 = std::min(d.width - 1, int(std::ceil(cx + radius)));
  const int y0 = std::max(0, int(std::floor(cy - radius))), y1 = std::min(d.height - 1, int(std::ceil(cy + radius)));
  if (x0 > x1 || y0 > y1) return;
  for (int ty = y0 / kTileSize; ty <= y1 / kTileSize; ++ty)
    for (int tx = x0 / kTileSize; tx <= x1 / kTileSize; ++tx) {
      TileData t = canvas.read_tile(ty * canvas.tiles_x() + tx);
      bool touched = false;
      for (int ly = 0; ly < kTileSize; ++ly)
        for (int lx = 0; lx < kTileSize; ++lx) {
          const int x = tx * kTileSize + lx, y = ty * kTileSize + ly;
          const float r2 = ((x + 0.5f - cx) * (x + 0.5f - cx) + (y + 0.5f - cy) * (y + 0.5f - cy)) / (radius * radius);
          if (x >= d.width || y >= d.height || r2 >= 1.f) continue;
          // The dome's column on top of the paint already there (whole cells of it).
          float h = height * (1.f - r2);
          auto at = [&](int z) { return (size_t(z) * kTileSize + ly) * kTileSize + lx; };
          int z = 0;
          while (z < d.depth && t.density[at(z)] >= 1.f) ++z;
          for (; z < d.depth && h > 0.f; ++z) {
            const size_t i = at(z);
            const float old = t.density[i], add = std::min(h, 1.f - old);
            if (add <= 0.f) continue;
            const float m = old + add;
            auto mix = [&](uint16_t& q, float v) { q = encode_unorm16((decode_unorm16(q) * old + v * add) / m); };
            mix(t.pigment_r[i], paint.ryb[0]);
            mix(t.pigment_y[i], paint.ryb[1]);
            mix(t.pigment_b[i], paint.ryb[2]);
            mix(t.oil[i], paint.oil);
            t.dryness[i] = encode_unorm16(decode_unorm16(t.dryness[i]) * old / m);  // fresh paint is wet
            t.density[i] = m;
            h -= add;
            touched = true;
          }
        }
      if (touched) canvas.write_tile(t);
    }
}

SimConfig stroke_config(const Stroke& stroke, const Device& device) {
  SimConfig cfg;
  cfg.device = device;
  cfg.canvas = stroke.canvas;
  cfg.brush = stroke.brush;
  if (stroke.window)
    cfg.window = Int3{(*stroke.window)[0], (*stroke.window)[1], std::min((*stroke.window)[2], stroke.canvas.depth)};
  if (stroke.tilt) cfg.params.grid.tilt = *stroke.tilt;
  if (stroke.paper_rgb)
    cfg.params.render.paper_rgb = Vec3((*stroke.paper_rgb)[0], (*stroke.paper_rgb)[1], (*stroke.paper_rgb)[2]);
  return cfg;
}

BrushPose rest_pose(const SimConfig& config) {
  BrushPose rest;
  rest.position = Vec3(config.canvas.width * 0.5f, config.canvas.height * 0.5f, config.brush.length * 1.5f);
  return rest;
}

BrushPose start_pose(const Stroke& stroke) {
  const StrokePlayer player(stroke);
  return player.pose_at(player.t_begin());
}

void write_painting(const std::string& path, const PaintingSnapshot& snapshot, const PaintingSnapshot* palette) {
  SaveOptions options;
  if (palette && palette->canvas.allocated_tiles() > 0) options.palette = &palette->canvas;
  save_painting(path, snapshot.canvas, snapshot.merged, snapshot.metadata, options);
}

Session::Session(const SimConfig& config, int undo_levels) : Session(config, rest_pose(config), undo_levels) {}

Session::Session(const SimConfig& config, const BrushPose& initial, int undo_levels)
    : sim_(std::make_unique<Simulator>(config, initial)), renderer_(config.device), undo_levels_(undo_levels) {
  WB_REQUIRE(undo_levels >= 0, "Session: undo_levels must be >= 0");
  renderer_.params() = config.params.render;
}

Session::~Session() = default;

std::unique_ptr<Session> Session::open(const std::string& path, const SimConfig& base, const OpenOptions& options) {
  Painting p = load_painting(path, base.device);
  if (options.palette) {
    if (!p.palette) return nullptr;
    p.canvas = std::move(*p.palette);
  }
  SimConfig cfg = base;
  cfg.canvas = p.canvas.dims();
  cfg.window.z = std::min(cfg.window.z, cfg.canvas.depth);
  const nlohmann::json& m = p.metadata;
  // What the painting records of how it was made; an entry this build cannot read costs that
  // entry (a warning), not the painting.
  auto warn = [&](const Error& e, const char* what) {
    std::fprintf(stderr, "wetbrush: warning: %s (the painting opens %s)\n", e.what(), what);
  };
  if (options.its_brush && m.contains("brush") && m["brush"].is_object()) {
    try {
      cfg.brush = brush_from_json(m["brush"], path, "metadata.brush");
    } catch (const Error& e) {
      warn(e, "with the default brush");
    }
  }
  if (m.contains("paper_rgb")) {
    const nlohmann::json& p = m["paper_rgb"];
    const auto unit = [](const nlohmann::json& v) {
      return v.is_number() && v.get<double>() >= 0.0 && v.get<double>() <= 1.0;
    };
    if (p.is_array() && p.size() == 3 && std::all_of(p.begin(), p.end(), unit))
      cfg.params.render.paper_rgb = Vec3(p[0].get<float>(), p[1].get<float>(), p[2].get<float>());
    else
      std::fprintf(stderr,
                   "wetbrush: warning: %s: metadata.paper_rgb is not three numbers in [0, 1] (the painting "
                   "opens with the default paper)\n",
                   path.c_str());
  }
  auto s = std::make_unique<Session>(cfg, options.undo_levels);
  if (m.contains("ground") && m["ground"].is_object()) {
    try {
      s->ground_ = ground_from_json(m["ground"], path, "metadata.ground");
    } catch (const Error& e) {
      warn(e, "without its ground record: recordings from it have no ground");
    }
  }
  s->write_canvas([&](TileStore& canvas) { canvas.copy_from(p.canvas); });
  return s;
}

void Session::reconfigure(const SimConfig& config) {
  WB_REQUIRE(config.canvas == dims(), "Session::reconfigure: the canvas size cannot change");
  replay_.reset();
  player_.reset();
  end_stroke();
  // The new simulator first: one the memory cannot hold is refused while the old one stays.
  auto next = std::make_unique<Simulator>(config, rest_pose(config));
  // The old simulator goes: its paint settles for good (with_settled_canvas would keep and put back
  // the window and particles, reads a settled simulator does not make), and its canvas is copied.
  sim_->settle();
  std::unique_ptr<Simulator> old = std::move(sim_);
  sim_ = std::move(next);
  sim_->replace_canvas([&](TileStore& canvas) { canvas.copy_from(old->canvas()); });
  old.reset();
  renderer_ = Renderer(config.device);
  renderer_.params() = config.params.render;
  recorder_.reset();  // the records' tiles are the same; a new record starts with the next stroke
}

void Session::lay_ground(const CanvasGround& ground) {
  sim_->lay_ground(ground, rgb_to_ryb(renderer_.params().paper_rgb));
  ground_ = ground;
  reset_undo_records();
}

// --- strokes ---------------------------------------------------------------------------------

void Session::begin_stroke(const BrushPose& pose, const PaintLoad& paint, bool keeps_its_paint) {
  sim_->reset_brush(pose);
  // A brush that is not refilled at every pen-down carries one load for the whole stroke.
  if (!paint.reload_on_pen_down && !keeps_its_paint) sim_->load_paint(paint);
}

void Session::capture_before_step(const BrushPose& to) {
  // Cells one step may change: the active window around the brush's footprint at the step's
  // start and end (the bristles' reach), snapped to the grid's window snap.
  const SimConfig& c = sim_->config();
  const int reach = int(c.brush.length + std::max(c.brush.width, c.brush.thickness)) +
                    std::max(c.window.x, c.window.y) / 2 + c.params.grid.window_snap + 2;
  const Vec3 a = sim_->brush().pose().position, b = to.position;
  recorder_.capture_rect(sim_->tiles(), int(std::min(a.x, b.x)) - reach, int(std::min(a.y, b.y)) - reach,
                         int(std::max(a.x, b.x)) + reach, int(std::max(a.y, b.y)) + reach);
  record_open_ = true;
}

void Session::step(const BrushPose* poses, int substeps, float dt) {
  WB_REQUIRE(substeps >= 1, "Session::step: at least one pose");
  if (undo_levels_ > 0) capture_before_step(poses[substeps - 1]);
  record_painted_ = true;  // poses carry no contact: any of them may touch
  sim_->step(poses, substeps, dt);
}

void Session::step(const StrokePlayer& player, const PlayerStep& step, std::span<const StrokeEvent> events,
                   bool reload) {
  if (undo_levels_ > 0) capture_before_step(player.pose_at(step.t));
  record_painted_ = record_painted_ || step.pen_down;
  for (const StrokeEvent& e : events)
    if (e.kind == StrokeEventKind::Dry) reset_undo_records();
  drive_step(*sim_, player, step, events, reload, poses_);
}

void Session::apply(const StrokeEvent& event) {
  // What a stroke file's reader checks of an event (the library's callers pass values unread).
  const auto unit = [](float v) { return std::isfinite(v) && v >= 0.f && v <= 1.f; };
  WB_REQUIRE(unit(event.ryb[0]) && unit(event.ryb[1]) && unit(event.ryb[2]) && unit(event.oil) && unit(event.load) &&
                 unit(event.fraction),
             std::string(to_string(event.kind)) + ": the pigment, oil, load and fraction must be in [0, 1]");
  if (event.kind == StrokeEventKind::Dry) reset_undo_records();
  sim_->apply(event);
}

bool Session::end_stroke() {
  // A record of lifted steps alone (the brush's travel, the last stroke's paint landing) is no
  // stroke: it stays open, and the next stroke's undo takes it too.
  if (!record_open_ || !record_painted_) return false;
  record_open_ = record_painted_ = false;
  TileDiff diff;
  const Int3 o = sim_->grid().window().origin(), n = sim_->grid().window().dims();
  sim_->with_settled_canvas([&](TileStore& c) {
    diff = recorder_.finish(c);
    // The tiles under the window, at rest now, start the next record, so that its undo comes back
    // to this canvas (paint in flight lands after the stroke).
    recorder_.capture_rect(c, o.x, o.y, o.x + n.x, o.y + n.y);
  });
  if (diff.empty()) return false;
  undo_.push_back(std::move(diff));
  while (int(undo_.size()) > undo_levels_) undo_.pop_front();
  redo_.clear();
  return true;
}

CanvasRect Session::restore(const TileDiff& d, bool after) {
  sim_->replace_canvas([&](TileStore& c) { after ? d.apply_after(c) : d.apply_before(c); });
  recorder_.reset();
  record_open_ = record_painted_ = false;
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  const int tiles_x = sim_->canvas().tiles_x();
  for (const TileSnapshot& t : d.before) {
    const int tx = t.tile_id % tiles_x, ty = t.tile_id / tiles_x;
    x0 = std::min(x0, tx * kTileSize), y0 = std::min(y0, ty * kTileSize);
    x1 = std::max(x1, (tx + 1) * kTileSize), y1 = std::max(y1, (ty + 1) * kTileSize);
  }
  return x1 < 0 ? CanvasRect{} : CanvasRect{x0, y0, x1 - x0, y1 - y0};
}

std::optional<CanvasRect> Session::move_record(std::deque<TileDiff>& from, std::deque<TileDiff>& to, bool after) {
  end_stroke();
  if (from.empty()) return std::nullopt;
  TileDiff d = std::move(from.back());
  from.pop_back();
  const CanvasRect r = restore(d, after);
  to.push_back(std::move(d));
  return r;
}

std::optional<CanvasRect> Session::undo() { return move_record(undo_, redo_, false); }

std::optional<CanvasRect> Session::redo() { return move_record(redo_, undo_, true); }

void Session::abandon_stroke() {
  replay_.reset();
  player_.reset();
  const std::vector<TileSnapshot> before = recorder_.take_before();
  record_open_ = record_painted_ = false;
  std::unique_ptr<Simulator> old = std::move(sim_);
  const SimConfig& config = old->config();
  sim_ = std::make_unique<Simulator>(config, rest_pose(config));
  sim_->replace_canvas([&](TileStore& canvas) {
    old->with_settled_canvas([&](TileStore& c) { canvas.copy_from(c); });
    for (const TileSnapshot& t : before) restore_tile(canvas, t);
  });
}

void Session::reset_undo_records() {
  recorder_.reset();
  record_open_ = record_painted_ = false;
  undo_.clear();
  redo_.clear();
}

void Session::write_canvas(const std::function<void(TileStore&)>& write) {
  sim_->replace_canvas(write);
  reset_undo_records();
}

// --- stroke files ----------------------------------------------------------------------------

void Session::begin_replay(const Stroke& stroke) {
  validate_stroke(stroke);
  WB_REQUIRE(stroke.canvas == dims(), stroke.source + ": the stroke's canvas (" + std::to_string(stroke.canvas.width) +
                                          " x " + std::to_string(stroke.canvas.height) + " x " +
                                          std::to_string(stroke.canvas.depth) + " cells) is not this session's");
  end_stroke();
  replay_.reset();
  player_.reset();
  // The stroke's brush, window, tilt and paper replace the session's where they differ.
  const SimConfig own = stroke_config(stroke, device());
  SimConfig want = config();
  want.brush = own.brush;
  if (stroke.window) want.window = own.window;
  if (stroke.tilt) want.params.grid.tilt = own.params.grid.tilt;
  if (stroke.paper_rgb) want.params.render.paper_rgb = own.params.render.paper_rgb;
  const Int3 w0 = config().window;
  if (brush_to_json(want.brush) != brush_to_json(config().brush) || want.window.x != w0.x || want.window.y != w0.y ||
      want.window.z != w0.z ||
      want.params.grid.tilt != config().params.grid.tilt)
    reconfigure(want);
  renderer_.params().paper_rgb = want.params.render.paper_rgb;
  // The stroke's canvas is primed as its file says, when this session's canvas is still blank.
  if (stroke.ground && !ground_ && sim_->census().total() == 0.0) lay_ground(*stroke.ground);
  player_ = std::make_unique<StrokePlayer>(stroke);
  replay_ = std::make_unique<Replay>(*sim_, *player_);
  begin_stroke(player_->pose_at(player_->t_begin()), stroke.paint);
}

bool Session::advance() {
  WB_REQUIRE(replay_ != nullptr, "Session::advance: no replay was begun");
  // A stroke file is one undo unit, lifted steps and all.
  record_painted_ = true;
  const bool more = undo_levels_ > 0 ? replay_->advance([this](const BrushPose& end) { capture_before_step(end); })
                                     : replay_->advance();
  if (more) return true;
  end_stroke();
  return false;
}

void Session::play(const Stroke& stroke) {
  begin_replay(stroke);
  while (advance()) {
  }
}

// --- the painting ----------------------------------------------------------------------------

Image Session::render(const Camera& camera) {
  const ParticleOverlay overlay = sim_->particle_overlay();
  return renderer_.render(sim_->tiles(), camera, sim_->live_window(), &overlay);
}

FloatImage Session::settled_map(FloatImage (Renderer::*map)(TileStore&, PaintWindow*)) {
  // The maps describe the paint, not a view of it: the default render parameters, as the
  // material maps' files (material_maps.h).
  FloatImage out;
  sim_->with_settled_canvas([&](TileStore& c) {
    Renderer r(device());
    out = (r.*map)(c, nullptr);
  });
  return out;
}

FloatImage Session::height_map() { return settled_map(&Renderer::render_height_map); }

FloatImage Session::normal_map() { return settled_map(&Renderer::render_normal_map); }

FloatImage Session::albedo() { return settled_map(&Renderer::render_albedo); }

std::optional<Vec3> Session::pick(int x, int y) {
  return renderer_.pigment_at(sim_->tiles(), x, y, sim_->live_window());
}

DabSize palette_dab_size(const SimConfig& config) {
  // The window's top is a lid nothing rises through, and a brush scrubbing the dab ploughs ridges
  // of about 4 cells over it: a dab to the lid has no room for them. The viscous solve's
  // iterations also grow with the depth of paint over the no-slip glass: 6-cell dabs in a
  // 12-cell window take 13 a step on average, 12-cell dabs 32 (docs/STUDIO.md "Palette").
  const CanvasDims& d = config.canvas;
  const float radius = std::max(4.f, 0.1f * float(std::min(d.width, d.height)));
  return {radius, std::min(0.6f * radius, 0.5f * float(std::min(config.window.z, d.depth)))};
}

void Session::put_paint(float cx, float cy, float radius, float height, const PaintLoad& paint) {
  WB_REQUIRE(std::isfinite(cx) && std::isfinite(cy) && std::isfinite(radius) && std::isfinite(height) &&
                 radius > 0.f && height > 0.f,
             "put_paint: the centre must be finite and the radius and height positive");
  sim_->replace_canvas([&](TileStore& canvas) { put_paint_dab(canvas, cx, cy, radius, height, paint); });
  reset_undo_records();
}

PaintingSnapshot Session::snapshot(const nlohmann::json& extra, const Image* merged) {
  const CanvasDims d = dims();
  // The copy on the session's device is rendered there; the snapshot keeps a host copy, which a
  // writer on another thread reads while the session paints on.
  TileStore copy = sim_->settled_canvas_copy(device());
  PaintingSnapshot s{TileStore(Device{}, d), merged ? *merged : renderer_.render(copy, Camera::top(d)),
                     nlohmann::json::object()};
  s.canvas.copy_from(copy);
  const Vec3 paper = renderer_.params().paper_rgb;
  s.metadata = {{"brush", brush_to_json(config().brush)},
                {"paper_rgb", {paper.x, paper.y, paper.z}},
                {"ground", ground_ ? ground_to_json(*ground_) : nlohmann::json(nullptr)},
                {"device", device().to_string()}};
  if (extra.is_object())
    for (const auto& [k, v] : extra.items()) s.metadata[k] = v;
  return s;
}

void Session::save(const std::string& path, const nlohmann::json& extra) { write_painting(path, snapshot(extra)); }

double Session::export_maps(const MaterialMapPaths& paths) {
  double scale = 0.0;
  sim_->with_settled_canvas([&](TileStore& c) { scale = write_material_maps(device(), c, paths); });
  return scale;
}

void Session::load(const std::string& path) {
  Painting p = load_painting(path, device());
  WB_REQUIRE(p.canvas.dims() == dims(), path + ": the painting's canvas is not this session's size");
  write_canvas([&](TileStore& canvas) { canvas.copy_from(p.canvas); });
}

void Session::load(Session& from) { load(from.canvas_copy(device())); }

void Session::load(const TileStore& from) {
  WB_REQUIRE(from.dims() == dims(), "Session::load: the canvases differ in size");
  write_canvas([&](TileStore& canvas) { canvas.copy_from(from); });
}

void Session::clear() {
  write_canvas([](TileStore& canvas) { canvas.clear(); });
  ground_.reset();
}

const Image& Session::update_image(CanvasImageCache& cache) {
  const ParticleOverlay overlay = sim_->particle_overlay();
  return cache.update(sim_->tiles(), sim_->live_window(), &overlay);
}

}  // namespace wb
