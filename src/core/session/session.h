// A painting session: the layer between the simulator and its users (the CLI, the studio and the
// Python module). It owns the simulator, its renderer, undo and the document (canvas, ground,
// paper, metadata), and its verbs are the one path each program takes to start a stroke, replay
// a stroke file, save, export and pick. Qt-free; one thread at a time (docs/ARCHITECTURE.md
// "Session").
#pragma once
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/canvas/ground.h"
#include "core/io/document.h"
#include "core/io/material_maps.h"
#include "core/io/stroke.h"
#include "core/io/stroke_player.h"
#include "core/io/undo_tiles.h"
#include "core/render/renderer.h"
#include "core/sim/replay.h"
#include "core/sim/simulator.h"

namespace wb {

/// The simulator's configuration a stroke file asks for on `device`: its canvas, brush, window
/// and tilt (parameters at their defaults otherwise; the caller may change any before use).
SimConfig stroke_config(const Stroke& stroke, const Device& device);

/// Where a session's brush waits before its first stroke: above the middle of the canvas.
BrushPose rest_pose(const SimConfig& config);
/// Where a stroke's brush starts (the player's pose at its first instant, in the air).
BrushPose start_pose(const Stroke& stroke);

/// Puts a dab of wet `paint` on the canvas, a dome `radius` cells across its half and
/// `height` cells high at its middle, on whatever paint is there (mixed by mass where they share
/// a cell). Touches only the tiles under the dab.
void put_paint_dab(TileStore& canvas, float cx, float cy, float radius, float height, const PaintLoad& paint);

/// A dab put out on a palette (the studio's wells): about a fifth of the canvas's smaller side
/// across, a third as high as wide (squeezed-out stiff paint), within half the window's depth.
struct DabSize {
  float radius = 0.f, height = 0.f;  ///< cells
};
DabSize palette_dab_size(const SimConfig& config);

/// A copy of the painting at rest, taken between two steps: what a save writes (any thread may
/// write it while the session paints on).
struct PaintingSnapshot {
  TileStore canvas;
  Image merged;  ///< the rendered painting, one pixel a cell
  nlohmann::json metadata;
};

/// Writes a snapshot as a painting file (atomically; document.h), with the studio's palette (a
/// snapshot of its own session) when given.
void write_painting(const std::string& path, const PaintingSnapshot& snapshot, const PaintingSnapshot* palette = nullptr);

class Session {
 public:
  /// A blank canvas, the brush waiting at `initial` (rest_pose by default). `undo_levels`
  /// strokes can be undone (0: no undo records, no cost).
  explicit Session(const SimConfig& config, int undo_levels = 0);
  Session(const SimConfig& config, const BrushPose& initial, int undo_levels = 0);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  struct OpenOptions {
    int undo_levels = 0;
    bool palette = false;    ///< open the palette saved with the painting (null when it has none)
    bool its_brush = true;   ///< the brush its metadata names, else `base`'s
  };
  /// A painting file opened on `base.device`, the simulator configured for its canvas (`base`
  /// gives the rest: brush, window, parameters, particles), its paper and its ground's record.
  static std::unique_ptr<Session> open(const std::string& path, const SimConfig& base, const OpenOptions& options);
  static std::unique_ptr<Session> open(const std::string& path, const SimConfig& base) {
    return open(path, base, OpenOptions{});
  }

  const SimConfig& config() const { return sim_->config(); }
  const Device& device() const { return sim_->device(); }
  const Simulator& sim() const { return *sim_; }
  Simulator& sim() { return *sim_; }
  Renderer& renderer() { return renderer_; }
  CanvasDims dims() const { return sim_->config().canvas; }
  /// The canvas's priming, when it has one (the paper colour is its primer's).
  const std::optional<CanvasGround>& ground() const { return ground_; }

  /// A new configuration (brush, parameters, window, device) on the same painting: the paint in
  /// flight settles into the canvas, which the new simulator takes over. Canvas sizes must agree.
  void reconfigure(const SimConfig& config);
  /// Primes the (empty) canvas with a woven ground of the paper's colour (Simulator::lay_ground).
  void lay_ground(const CanvasGround& ground);

  // --- strokes: the one stroke-start path, and the undo unit ---
  /// A stroke starts: the brush is put at rest at `pose` and, when the paint is not reloaded at
  /// every pen-down, loaded once with `paint` for the whole stroke, unless `keeps_its_paint` (a
  /// brush carried in from the palette with its paint sample by sample).
  void begin_stroke(const BrushPose& pose, const PaintLoad& paint, bool keeps_its_paint = false);
  /// One step of `dt` s through the sub-step poses (Simulator::step); with undo on, the tiles the
  /// step may change are recorded first.
  void step(const BrushPose* poses, int substeps, float dt);
  /// One step of a stroke player (drive_step: its events, the pen-down reload when `reload`, its
  /// sub-step poses), recorded for undo as step() is.
  void step(const StrokePlayer& player, const PlayerStep& step, std::span<const StrokeEvent> events, bool reload);
  /// A palette event (dip, wipe, clean, dry). Drying starts a new undo history: restoring wet
  /// tiles over the dried layer would undo the drying too.
  void apply(const StrokeEvent& event);
  /// The stroke is over: its undo record is kept when the pen came down in it and the canvas
  /// changed (true). Lifted steps alone stay in the open record, for the next stroke's undo.
  bool end_stroke();
  bool can_undo() const { return !undo_.empty(); }
  bool can_redo() const { return !redo_.empty(); }
  /// Undoes / redoes the last stroke: the canvas rectangle it wrote (none when there was none).
  std::optional<CanvasRect> undo();
  std::optional<CanvasRect> redo();
  /// A step failed and left the simulation half-made: a new simulator takes the canvas as it was
  /// before the stroke (the undo record's tiles; the paint on the brush is lost). Throws when the
  /// canvas cannot be read back from the device.
  void abandon_stroke();

  // --- stroke files ---
  /// Starts replaying `stroke` (validated; its canvas must be this session's size): the stroke's
  /// ground is laid on a blank canvas, its brush and window replace the session's when they
  /// differ, and the stroke starts. advance() then runs it a step at a time.
  void begin_replay(const Stroke& stroke);
  /// The replay's next step; false when the stroke is over (its undo record is then closed).
  bool advance();
  /// The replay in progress (null when none).
  const Replay* replay() const { return replay_.get(); }
  /// The whole stroke in one call: begin_replay and advance to its end.
  void play(const Stroke& stroke);

  // --- the painting: pictures, maps, files ---
  /// Puts every particle back into the grid and writes the window to the canvas.
  void settle() { sim_->settle(); }
  /// The painting now through `camera`, with the live paint and particles.
  Image render(const Camera& camera);
  /// Maps of the painting at rest, one value a canvas cell (Renderer: height in cells, unit
  /// normals, unlit colour).
  FloatImage height_map();
  FloatImage normal_map();
  FloatImage albedo();
  /// The pigment (RYB) at canvas cell (x, y), none where the canvas is bare.
  std::optional<Vec3> pick(int x, int y);
  /// A dome of fresh paint of `paint`'s colour and oil, `height` cells high at its centre,
  /// `radius` cells across, on the paint already there (the studio's palette wells).
  void put_paint(float cx, float cy, float radius, float height, const PaintLoad& paint);
  /// The painting at rest as a snapshot to save; `merged` is used as the rendered painting when
  /// given (a view that has it), else it is rendered. `extra` adds to the metadata.
  PaintingSnapshot snapshot(const nlohmann::json& extra = {}, const Image* merged = nullptr);
  /// Saves the painting (snapshot + write_painting).
  void save(const std::string& path, const nlohmann::json& extra = {});
  /// Writes the material maps of the painting at rest (the one writer: material_maps.h).
  double export_maps(const MaterialMapPaths& paths);
  /// Replaces the canvas by a painting file's (same size; its ground comes with it).
  void load(const std::string& path);
  /// Takes another session's painting at rest (same size; the palette of an opened painting).
  void load(Session& from);
  /// Takes a canvas's paint (same size; a built-in test volume of `wetbrush render`).
  void load(const TileStore& canvas);
  /// A blank canvas (paint in flight dropped; the books say so).
  void clear();
  /// The image `cache` keeps of this painting brought up to date where the paint changed, with
  /// the live window and the particles (the studio's view).
  const Image& update_image(CanvasImageCache& cache);
  /// A copy of the painting at rest on `device` (the relief exports, the palette's save).
  TileStore canvas_copy(const Device& device) { return sim_->settled_canvas_copy(device); }

 private:
  /// Records the tiles a step from the brush's pose now to `to` may change (undo on).
  void capture_before_step(const BrushPose& to);
  /// Writes a record's tiles (before or after) and returns the rectangle they cover.
  CanvasRect restore(const TileDiff& d, bool after);
  /// One of the renderer's maps of the painting at rest.
  FloatImage settled_map(FloatImage (Renderer::*map)(TileStore&, PaintWindow*));
  /// The last record of `from` restored (its tiles after the stroke when `after`) and moved to `to`.
  std::optional<CanvasRect> move_record(std::deque<TileDiff>& from, std::deque<TileDiff>& to, bool after);
  void reset_undo_records();
  /// Replaces the canvas's tiles (undo, redo, load) and drops what records described the old one.
  void write_canvas(const std::function<void(TileStore&)>& write);

  std::unique_ptr<Simulator> sim_;
  Renderer renderer_;
  std::optional<CanvasGround> ground_;
  int undo_levels_ = 0;
  StrokeTileRecorder recorder_;
  bool record_open_ = false;
  bool record_painted_ = false;  ///< the open record has a step with the pen down
  std::deque<TileDiff> undo_, redo_;
  std::vector<BrushPose> poses_;  ///< a step's sub-step poses (reused)
  std::unique_ptr<StrokePlayer> player_;
  std::unique_ptr<Replay> replay_;
};

}  // namespace wb
