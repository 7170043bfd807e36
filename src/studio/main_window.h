// The studio's main window: the canvas view in the middle, brush / paint / view panels,
// menus (files, undo, canvas, recording), status bar (simulation rate, particles, device,
// preset, frame rate), autosave and crash recovery.
#pragma once
#include <QDockWidget>
#include <QLabel>
#include <QMainWindow>
#include <QTimer>
#include <QUndoStack>

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#if WB_WITH_MEDIA
#include "media/timelapse.h"
#endif
#include "core/io/undo_tiles.h"
#include "studio/brush_preview.h"
#include "studio/canvas_view.h"
#include "studio/palette.h"
#include "studio/panels.h"
#include "studio/pen_clock.h"
#include "studio/sim_thread.h"

namespace wb::studio {

struct StudioOptions {
  Device device{};
  QualityPreset preset = QualityPreset::cpu();
  std::optional<BrushSpec> brush;  ///< starting brush (default: the preset's round brush)
  QString open_path;            ///< painting to open at start
  QString data_dir;             ///< presets, recovery file (default: the platform's app data folder)
  bool offer_recovery = true;
  int autosave_interval_s = 180;
  ViewKind view = ViewKind::Auto;  ///< how the canvas and the palette are drawn (--view)
};

/// Undo limit: whole strokes kept (each holds only the tiles it changed, zstd-compressed).
inline constexpr int kUndoLimit = 64;

class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  explicit MainWindow(const StudioOptions& options, QWidget* parent = nullptr);
  ~MainWindow() override;

  CanvasView* view() const { return view_; }
  SimThread* sim() const { return sim_.get(); }
  QUndoStack* undo_stack() const { return undo_; }
  BrushPanel* brush_panel() const { return brush_panel_; }
  PaintPanel* paint_panel() const { return paint_panel_; }
  QString current_path() const { return path_; }
  bool modified() const { return !undo_->isClean() || dirty_; }
  QString recovery_path() const;

  // Actions (also used by tests). Saves and exports return after the file is written when
  // `wait` is set; otherwise the write happens on a worker and the UI continues.
  bool save_to(const QString& path, bool wait = false);
  bool open_from(const QString& path);
  bool export_png(const QString& path);
  bool export_maps(const QString& height_path, const QString& normal_path);
#if WB_WITH_MEDIA  // src/media: not in a -DWB_MEDIA=OFF build
  /// Relief exports (media/relief_export.h, the CLI's defaults): the paths not empty are written.
  bool export_relief(const QString& exr_path, const QString& stl_path, const QString& glb_path);
  /// The session's recording replayed on a fresh simulator into an MP4 time-lapse
  /// (media/timelapse.h), with a progress dialog that can cancel.
  bool export_timelapse(const QString& path, const TimelapseOptions& options = {});
#endif
  bool save_recording(const QString& path);
  /// A new canvas, primed with `ground` (a smooth ground lays nothing).
  void new_canvas(int width, int height, QColor paper, const CanvasGround& ground = {});
  /// The canvas's tilt from the table, degrees in [0, 90] (GridParams::tilt): the canvas's
  /// simulator is made anew with the painting on it; the palette stays flat.
  void set_tilt(float degrees);
  /// Why a canvas of this size cannot take this ground (too thick for the paint depth, or more
  /// paint than a painting may hold); empty when it can.
  QString ground_refusal(int width, int height, const CanvasGround& ground) const;
  void dip(const PaintLoad& p);
  static StrokeEvent dip_event(const PaintLoad& p);
  void wipe(float fraction);
  void clean_brush();
  void dry_canvas();
  /// The eyedropper: puts the pigment of the paint shown at this canvas point (cells) into the
  /// selected well. Returns it, or nothing over bare canvas (the well is left as it was).
  std::optional<std::array<float, 3>> pick_color(QPointF canvas, SimThread* from = nullptr);
  PalettePanel* palette() const { return palette_; }
  /// True while the brush is on the palette (its paint there, sample by sample).
  bool brush_on_palette() const { return brush_on_palette_; }
  /// Carries the brush with its paint to the palette (`to_palette`) or back to the canvas: the
  /// side it leaves simulates its time line to the end first; the side it reaches starts a new
  /// recording with it. Does nothing when the brush is there already.
  void carry_brush(bool to_palette);
  ViewPanel* view_panel() const { return view_panel_; }
  BrushPreview* brush_preview() const { return brush_preview_; }
  /// The oblique view as last rendered (null until the view is turned on).
  QImage oblique_image() const { return oblique_image_; }
  /// How many oblique views have arrived (tests wait on it).
  int oblique_renders() const { return oblique_renders_; }
  /// Blocks until the simulation has consumed every input so far and the last stroke's undo
  /// record has arrived (tests). With `present`, the window goes on drawing the frames that come
  /// meanwhile, as it does for a painter who waits (the demo's latency and frame rate).
  void settle(bool present = false);

 protected:
  void closeEvent(QCloseEvent* e) override;

 private:
  void build_menus();
  void push_clock(const ClockOutput& out);
  void send_event(StrokeEvent e);
  void update_status();
  void update_title();
  void add_recent(const QString& path);
  void rebuild_recent_menu();
  /// Edit > Memory limit: the budget (mem::set_budget), kept in the settings for the next start.
  void ask_memory_limit();
  /// Runs an export's `write` on the simulation thread and waits for it; a failure is shown.
  bool run_export(std::function<void(SimThread&)> write);
  bool maybe_save();
  /// Returns when every save in flight has succeeded or failed (and said so).
  void wait_for_saves();
  void autosave();
  void check_recovery();
  bool write_snapshot(const QString& path, bool wait, bool user_save);
  /// Asks for a new oblique view once the simulation is idle (coalesced).
  void refresh_oblique();

  StudioOptions options_;
  std::unique_ptr<SimThread> sim_;
  PenClock clock_;
  CanvasView* view_ = nullptr;
  BrushPanel* brush_panel_ = nullptr;
  PaintPanel* paint_panel_ = nullptr;
  PalettePanel* palette_ = nullptr;
  bool brush_on_palette_ = false;
  float tilt_ = 0.f;  ///< the canvas's tilt from the table, degrees
  ViewPanel* view_panel_ = nullptr;
  BrushPreview* brush_preview_ = nullptr;
  QUndoStack* undo_ = nullptr;
  QMenu* recent_menu_ = nullptr;
  QLabel* status_sim_ = nullptr;
  QLabel* status_device_ = nullptr;
  QLabel* status_view_ = nullptr;
  QLabel* status_behind_ = nullptr;
  QTimer status_timer_, hold_timer_, autosave_timer_, idle_save_timer_;
  std::vector<StrokeEvent> pending_events_;  ///< palette actions while the pen is down
  QString path_;
  bool dirty_ = false;           ///< changes not in the undo stack (dry, open, new)
  bool autosave_due_ = false;
  // Snapshots are taken in the order they are asked for (the simulation thread's queue): the
  // serial of each, of the latest autosave asked for and of the latest user save that succeeded
  // decide whether the recovery file is older than the saved painting (then it goes).
  int64_t snapshot_serial_ = 0, autosave_serial_ = 0, saved_serial_ = 0;
  int64_t frames_at_ = 0;
  double frames_t_ = 0.0;
  double view_fps_ = 0.0;
  int saves_in_flight_ = 0;
  // The oblique view: its dock, the last image, and a timer that asks for a new one when the
  // canvas changed and the simulation is idle (a CPU render of the whole canvas takes a while).
  QDockWidget* oblique_dock_ = nullptr;
  QLabel* oblique_label_ = nullptr;
  QImage oblique_image_;
  int oblique_renders_ = 0;
  QTimer oblique_timer_;
  bool light_dragging_ = false;
  float drag_azimuth_ = 0.f, drag_elevation_ = 0.f;
};

}  // namespace wb::studio
