// The studio's simulation thread: owns the painting's Session (core/session/session.h: the
// simulator, the renderer, the undo records, the document) and the session recording; its
// pictures (canvas image, brush picture) are FrameCache's. The UI thread
// only enqueues time-stamped pen
// samples, palette events and commands, and takes the latest rendered pixels; it never waits
// for a step. Steps run at the fixed dt of the session time line (pen_clock.h) through the
// same StrokePlayer that `wetbrush replay` uses, so a saved recording replays to the same canvas.
#pragma once
#include <QImage>
#include <QObject>
#include <QRect>

#include <array>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "core/io/stroke_player.h"
#include "core/session/session.h"
#include "studio/frame_cache.h"
#include "studio/pen_clock.h"
#include "studio/preset.h"
#include "studio/session.h"

namespace wb::studio {

/// Where the simulation thread's wall time went since it started, seconds (docs/perf/studio.md).
struct WorkerTimes {
  double commands = 0.0;  ///< posted commands: brush changes, undo, snapshots for saves
  double player = 0.0;    ///< session time line: stroke player rebuilds and step lookup
  double undo = 0.0;      ///< the settled undo record after a stroke (the capture before a step is in `step`)
  double step = 0.0;      ///< Session::step: the undo capture and Simulator::step
  double render = 0.0;    ///< incremental re-render of the canvas image and its copy to the view
  double idle = 0.0;      ///< waiting for input
};

/// The wall times of the steps since the thread started, in bins of kBinMs (the last holds every
/// longer step): a painting's median step and tail without a time kept for every step.
struct StepTimes {
  static constexpr int kBins = 1000;
  static constexpr double kBinMs = 0.25;
  std::array<int64_t, kBins> count{};
  void add(double ms);
  /// The q-quantile (nearest rank; the bin's upper edge, ms) of the steps counted since `before`
  /// (an earlier copy of this); 0 when there are none.
  double quantile_since(const StepTimes& before, double q) const;
};

/// What the status bar shows; updated by the worker about twice a second.
struct SimStatus {
  double steps_per_s = 0.0;     ///< simulation steps per wall second (last ~0.5 s of activity)
  double step_ms = 0.0;         ///< median wall time of one step
  int64_t steps = 0;            ///< steps done in this session
  int64_t particles = -1;       ///< liquid particles (-1: the simulator has none)
  double lag_s = 0.0;           ///< session time not simulated yet
  /// Session seconds simulated per wall second over the last second, measured only while the
  /// simulation had steps waiting throughout it (-1: it caught up within the last second, so it
  /// keeps up). Below 1: the simulation falls behind real time.
  double realtime_factor = -1.0;
  int64_t brush_samples = 0;    ///< the simulated brush's bristles x samples (cost estimates)
  Int3 window{};                ///< the simulated window, cells (cost estimates)
  bool idle = true;
  std::string device;
  std::array<float, 3> brush_ryb{};  ///< mean colour of the paint on the brush (RYB), from the device
  float brush_amount = 0.f;          ///< how full the brush is: load / potential capacity
  std::string error;            ///< first error; stepping stops, the document is kept
  int64_t faults = 0;           ///< failed steps recovered from (the stroke ended, the canvas as before it)
  WorkerTimes times;
  StepTimes step_times;
};

class SimThread : public QObject {
  Q_OBJECT
 public:
  /// `undo_levels`: strokes the painting's Session keeps for undo (0: none, the palette).
  SimThread(const SimConfig& config, const RenderParams& render, int undo_levels, QObject* parent = nullptr);
  ~SimThread() override;

  // --- called from the UI thread: never block on the simulation ---------------------------
  /// Appends clock output (samples and events in time order) to the session.
  void push(const ClockOutput& out);
  /// Runs `fn` on the simulation thread between steps (with exclusive access).
  void post(std::function<void(SimThread&)> fn);
  /// Copies the pixels that changed since the last call into `canvas` (the full canvas
  /// image, one pixel per cell); returns the changed rectangle (empty when nothing changed) and
  /// the pen events whose steps these pixels show first.
  FrameUpdate take_frame(QImage& canvas);
  SimStatus status() const;
  /// The recording so far (a copy).
  Stroke recording() const;
  /// True while the recording reproduces the canvas from a blank one.
  bool recording_from_blank() const { return session_.from_blank(); }
  /// Blocks until every input pushed so far has been simulated (tests and shutdown only).
  void wait_idle();
  /// Every input pushed so far has been simulated (what wait_idle waits for).
  bool is_idle() const;
  /// Wet paint still ran at the end of the last step simulated (Simulator::paint_running): the
  /// time line goes on while the pen is away (PenClock::air).
  bool paint_running() const { return paint_running_.load(std::memory_order_relaxed); }
  /// The paint still runs and every input so far has been simulated: the pen clock may extend the
  /// time line (PenClock::tick).
  bool paint_runs_on() const { return paint_running() && is_idle(); }

  // --- on the simulation thread (inside post()) -----------------------------------------
  Session& session() { return *doc_; }
  Simulator& sim() { return doc_->sim(); }
  Renderer& renderer() { return doc_->renderer(); }
  /// A new configuration (brush, canvas, parameters): the painting's Session takes it over with
  /// its canvas when `keep_canvas` and the size holds (Session::reconfigure), else a new one starts.
  void rebuild(const SimConfig& config, bool keep_canvas);
  /// The painting of `path` replaces this one (its canvas size, brush and paper; Session::open):
  /// its palette instead when `palette` (false when the file has none).
  bool open(const std::string& path, bool palette);
  /// Undoes (or redoes) the last stroke the Session recorded: the time line is simulated to its
  /// end first, and a new recording starts from the canvas as it is then.
  void undo_stroke(bool redo);
  /// Starts a new recording (after undo, open, brush change): the next press begins it.
  void restart_recording(bool from_blank);
  /// Re-renders the whole canvas (light, paper, new canvas).
  void invalidate_all();
  void invalidate_rect(int x0, int y0, int x1, int y1);
  /// The whole canvas rendered now (one pixel per cell).
  Image canvas_image();
  /// Renders the whole canvas from `elevation_deg` above, at most `max_width` pixels wide,
  /// under the view's light, and hands it to the UI (obliqueReady).
  void render_oblique(float elevation_deg, int max_width);
  const SimConfig& config() const { return config_; }
  /// Simulates every step the inputs so far allow (before a restart or a snapshot).
  void drain();
  /// Paint the brush holds (the palette's current well) for recordings that start now.
  void set_paint(const PaintLoad& p) { paint_ = p; }
  const PaintLoad& paint() const { return paint_; }
  /// The brush leaves this canvas for the other (the palette, or back): the time line is
  /// simulated to its end, and the brush's paint, sample by sample, is returned and taken off it.
  BristleLoadHost give_brush_paint();
  /// The brush arrives with this paint (give_brush_paint of the other canvas); a new recording
  /// starts, whose first step keeps that paint instead of loading the well's.
  void receive_brush_paint(const BristleLoadHost& paint);
  /// Primes the blank canvas with `g` in the paper's colour (Session::lay_ground); the ground
  /// is the canvas's from then on: saved with the painting and with every recording.
  void prime(const CanvasGround& g);
  /// The brush's pose and paint as of the last rendered frame (the preview and the swatch).
  BrushPicture brush_picture() const;

 Q_SIGNALS:
  void frameReady();
  /// One stroke finished and the Session keeps its undo record.
  void strokeFinished();
  void failed(QString message);
  /// The oblique view asked for by render_oblique().
  void obliqueReady(QImage image);

 private:
  void run();
  /// Logs an exception with its source location and tells the window its message.
  void fail(const std::exception& e);
  bool step_available() { return !failed_ && doc_ && session_.has_step(); }
  /// One step of the time line; a step that throws (a device fault, a failed allocation) is
  /// recovered from (recover) rather than left half-made.
  void run_step(const SessionStep& step);
  void step_once(const SessionStep& step);
  /// The stroke a step failed in ends: the simulator is made anew on the canvas as it was before
  /// the stroke (Session::abandon_stroke), the painter is told, and painting and saving go on.
  void recover(const std::exception& e);
  /// A new time line for the recording, the old one not simulated further.
  void begin_recording(bool from_blank);
  void finish_stroke();
  /// FrameCache::render, and the view told of a new front image.
  void render(double min_interval);
  void publish_status(bool force);

  SimConfig config_;
  RenderParams render_;  ///< the view's render parameters, for every Session made here
  int undo_levels_ = 0;
  std::unique_ptr<Session> doc_;  ///< the painting's session
  PaintLoad paint_{};
  bool carried_paint_ = false;  ///< the brush holds paint carried in: the next recording loads none
  /// After a failed stroke: samples are dropped until the pen comes down after a lift.
  bool dropping_ = false;
  bool lifted_since_fault_ = false;

  // Inputs (UI -> worker).
  mutable std::mutex in_mu_;
  std::condition_variable in_cv_, idle_cv_;
  std::deque<PenSample> in_samples_;
  std::deque<StrokeEvent> in_events_;
  std::deque<std::function<void(SimThread&)>> in_cmds_;
  /// Pen events appended to the time line and not simulated yet (worker only), in session order.
  std::deque<PenEventTime> pending_inputs_;
  bool quit_ = false;
  bool busy_ = false;
  std::atomic<bool> paint_running_{false};

  SessionTimeline session_;  ///< the time line and its recording

  // Frames (worker -> UI): the canvas image and the brush picture.
  FrameCache frames_;

  mutable std::mutex status_mu_;
  SimStatus status_;
  int64_t steps_ = 0;
  int64_t rate_steps_ = 0;
  double rate_t0_ = 0.0;
  double busy_since_ = 0.0;        ///< since when steps have been waiting without a break (0: idle)
  std::deque<double> step_ends_;  ///< wall times the steps of the last second ended
  double last_status_ = 0.0;
  bool failed_ = false;
  WorkerTimes times_;  ///< worker only; copied into status_ with it
  StepTimes step_times_;  ///< worker only; copied into status_ with it

  std::thread thread_;
};

/// Exact step boundary arithmetic: t rounded to the step grid (values are multiples of 1/1024).
inline bool same_time(double a, double b) { return a == b; }

}  // namespace wb::studio
