#include "studio/sim_thread.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/color/ryb.h"
#include "core/exec/error.h"
#include "core/sim/replay.h"

namespace wb::studio {
namespace {

/// Seconds between the frames rendered while the simulation has steps waiting (caught up, it
/// renders at once).
constexpr double kBehindFrameInterval = 0.2;

/// Adds the time since `since` to `bucket`; returns now.
double lap(double& bucket, double since) {
  const double now = wall_now();
  bucket += now - since;
  return now;
}

}  // namespace

SimThread::SimThread(const SimConfig& config, const RenderParams& render, int undo_levels, QObject* parent)
    : QObject(parent), config_(config), render_(render), undo_levels_(undo_levels) {
  status_.device = config.device.to_string();
  // The simulator and the first full render are built on the worker: a big canvas must not
  // hold up the window.
  post([](SimThread& self) { self.rebuild(self.config_, false); });
  thread_ = std::thread([this] { run(); });
}

SimThread::~SimThread() {
  {
    std::lock_guard lk(in_mu_);
    quit_ = true;
  }
  in_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void SimThread::push(const ClockOutput& out) {
  if (out.samples.empty() && out.events.empty()) return;
  post([out](SimThread& self) {
    if (self.dropping_) {
      // After a stroke that failed, nothing until the pen comes down again after a lift: the rest
      // of that stroke and the lifted pen's path are not simulated (a new recording starts with
      // the next stroke).
      ClockOutput rest = out;
      auto next = rest.samples.begin();
      for (; next != rest.samples.end(); ++next) {
        if (!next->down) self.lifted_since_fault_ = true;
        else if (self.lifted_since_fault_) break;
      }
      self.dropping_ = next == rest.samples.end();
      rest.samples.erase(rest.samples.begin(), next);
      self.session_.append(rest);
      return;
    }
    self.session_.append(out);
    if (out.input) self.pending_inputs_.push_back(*out.input);
  });
}

void SimThread::post(std::function<void(SimThread&)> fn) {
  {
    std::lock_guard lk(in_mu_);
    in_cmds_.push_back(std::move(fn));
  }
  in_cv_.notify_all();
}

void SimThread::wait_idle() {
  std::unique_lock lk(in_mu_);
  idle_cv_.wait(lk, [&] { return quit_ || (in_cmds_.empty() && !busy_); });
}

bool SimThread::is_idle() const {
  std::lock_guard lk(in_mu_);
  return quit_ || (in_cmds_.empty() && !busy_);
}

Stroke SimThread::recording() const { return session_.recording(); }

SimStatus SimThread::status() const {
  std::lock_guard lk(status_mu_);
  return status_;
}

FrameUpdate SimThread::take_frame(QImage& canvas) { return frames_.take(canvas); }

// --- simulation thread ------------------------------------------------------------------

void SimThread::rebuild(const SimConfig& config, bool keep_canvas) {
  // Finish the old time line on the old simulator first.
  if (doc_ && !failed_) drain();
  finish_stroke();
  const bool same_dims = doc_ && doc_->dims() == config.canvas;
  if (doc_) render_ = doc_->renderer().params();  // the view's light and paper as they are now
  // Nothing painted in this recording: a new one from the blank (primed) canvas is the same.
  const bool painted = session_.painted();
  const bool same_session = keep_canvas && same_dims;
  if (same_session) {
    // The paint that was in flight comes too (Session::reconfigure settles it); a configuration
    // the memory cannot hold is refused while the old one, and its painting, stay.
    doc_->reconfigure(config);
  } else {
    auto next = std::make_unique<Session>(config, undo_levels_);
    doc_ = std::move(next);
  }
  doc_->renderer().params() = render_;
  config_ = config;
  carried_paint_ = false;  // a new brush is clean: its first stroke loads the well's paint
  restart_recording(session_.from_blank() && !(same_session && painted));
  if (!same_session) frames_.reset(*doc_);  // the image cache draws with the new session's renderer
  {
    std::lock_guard lk(status_mu_);
    status_.device = config.device.to_string();
  }
  invalidate_all();
  render(0.0);
}

bool SimThread::open(const std::string& path, bool palette) {
  if (doc_ && !failed_) drain();
  finish_stroke();
  // The painting opens with the brush in the painter's hand (the brush panel's).
  Session::OpenOptions o;
  o.undo_levels = palette ? 0 : undo_levels_;
  o.palette = palette;
  o.its_brush = false;
  std::unique_ptr<Session> next = Session::open(path, config_, o);
  if (!next) return false;
  if (doc_) render_ = doc_->renderer().params();
  // The studio's view keeps its light and its paper is the painting's.
  const Vec3 paper = next->renderer().params().paper_rgb;
  doc_ = std::move(next);
  render_.paper_rgb = paper;
  doc_->renderer().params() = render_;
  config_ = doc_->config();
  carried_paint_ = false;
  restart_recording(false);
  frames_.reset(*doc_);
  invalidate_all();
  render(0.0);
  return true;
}

void SimThread::undo_stroke(bool redo) {
  restart_recording(false);
  if (const std::optional<CanvasRect> r = redo ? doc_->redo() : doc_->undo())
    invalidate_rect(r->x0, r->y0, r->x0 + r->width, r->y0 + r->height);
}

void SimThread::restart_recording(bool from_blank) {
  // The old time line is simulated to its end first, and its open stroke closed.
  if (!failed_) drain();
  finish_stroke();
  begin_recording(from_blank);
}

void SimThread::begin_recording(bool from_blank) {
  Stroke header;
  header.canvas = config_.canvas;
  header.brush = config_.brush;
  header.paint = paint_;
  header.ground = doc_ ? doc_->ground() : std::nullopt;
  if (config_.params.grid.tilt > 0.f) header.tilt = config_.params.grid.tilt;
  header.paint.reload_on_pen_down = false;  // the studio's brush stays dirty between strokes
  const Vec3 paper = render_.paper_rgb;
  header.paper_rgb = std::array<float, 3>{paper.x, paper.y, paper.z};
  header.window = std::array<int, 3>{config_.window.x, config_.window.y, config_.window.z};  // the replay's window
  header.dt = kStepDt;
  header.lead_in = kLeadIn;
  header.lead_out = 0.0;
  header.source = "studio session";
  session_.restart(std::move(header), from_blank);
  pending_inputs_.clear();  // inputs past the old time line's last step: never simulated
}

BristleLoadHost SimThread::give_brush_paint() {
  drain();
  finish_stroke();
  BristleLoadHost paint = sim().brush_paint();
  sim().clean();  // the brush leaves: its paint goes with it (the books say so)
  return paint;
}

void SimThread::receive_brush_paint(const BristleLoadHost& paint) {
  drain();
  finish_stroke();
  sim().set_brush_paint(paint);
  // The recording goes on from here with the brush as it came (its steps load nothing); a replay
  // of it starts with the carried paint's mean colour, oil and fill on every sample.
  const PaintLoad carried = sim().brush_mean_paint(paint_);
  const PaintLoad well = paint_;
  paint_ = carried;
  restart_recording(false);
  paint_ = well;
  carried_paint_ = true;
}

void SimThread::prime(const CanvasGround& g) {
  doc_->lay_ground(g);
  invalidate_all();
}

void SimThread::invalidate_all() { frames_.invalidate_all(); }

void SimThread::invalidate_rect(int x0, int y0, int x1, int y1) { frames_.invalidate_rect(x0, y0, x1, y1); }

BrushPicture SimThread::brush_picture() const { return frames_.brush_picture(); }

Image SimThread::canvas_image() { return doc_ ? frames_.canvas_image(*doc_) : Image{}; }

void SimThread::render_oblique(float elevation_deg, int max_width) {
  if (!doc_) return;
  const CanvasDims d = doc_->dims();
  const float zoom = std::min(1.f, float(max_width) / float(d.width));
  const Image img = doc_->render(Camera::oblique(d, elevation_deg, zoom));
  QImage q(img.width, img.height, QImage::Format_RGBA8888);
  for (int y = 0; y < img.height; ++y) std::memcpy(q.scanLine(y), img.at(0, y), size_t(img.width) * 4);
  Q_EMIT obliqueReady(q);
}

void SimThread::drain() {
  SessionStep step;
  while (!failed_ && doc_ && session_.next_step(step)) run_step(step);
}

void SimThread::run_step(const SessionStep& s) {
  try {
    step_once(s);
  } catch (const std::exception& e) {
    recover(e);
  }
}

void SimThread::recover(const std::exception& e) {
  std::fprintf(stderr, "wetbrush-studio: a step failed: %s\n", e.what());
  // The failed step left the simulation half-made (window, particles, brush): all of it goes with
  // the simulator, and the canvas returns to where the stroke began: the undo record's "before"
  // of every tile the stroke may have touched (it never reached the others). The paint the brush
  // held goes too; its next stroke loads the well's.
  try {
    doc_->abandon_stroke();
  } catch (const std::exception& again) {
    // Nothing can be read back from the device (a fault that stays): the last autosave holds the
    // painting, and the studio offers it when it starts again.
    doc_.reset();
    failed_ = true;
    const std::string m = "the device failed (" + user_message(e) + ") and the painting cannot be read back from it (" +
                          user_message(again) + "): quit and start the studio again to recover the last autosave";
    {
      std::lock_guard lk(status_mu_);
      status_.error = m;
    }
    std::fprintf(stderr, "wetbrush-studio: %s\n", again.what());
    Q_EMIT failed(QString::fromStdString(m));
    return;
  }
  carried_paint_ = false;
  dropping_ = true;
  lifted_since_fault_ = !session_.pen_down_now();
  pending_inputs_.clear();
  begin_recording(false);
  invalidate_all();
  {
    std::lock_guard lk(status_mu_);
    ++status_.faults;
  }
  Q_EMIT failed(QString::fromStdString("the stroke could not be finished (" + user_message(e) +
                                       "): the painting is as it was before it; save it now"));
}

void StepTimes::add(double ms) {
  const double b = ms / kBinMs;
  ++count[b < double(kBins - 1) ? size_t(b > 0.0 ? b : 0.0) : size_t(kBins - 1)];
}

double StepTimes::quantile_since(const StepTimes& before, double q) const {
  int64_t n = 0;
  for (int i = 0; i < kBins; ++i) n += count[size_t(i)] - before.count[size_t(i)];
  if (n <= 0) return 0.0;
  const int64_t rank = std::max<int64_t>(1, int64_t(std::ceil(q * double(n))));
  int64_t seen = 0;
  for (int i = 0; i < kBins; ++i) {
    seen += count[size_t(i)] - before.count[size_t(i)];
    if (seen >= rank) return double(i + 1) * kBinMs;
  }
  return double(kBins) * kBinMs;
}

void SimThread::step_once(const SessionStep& s) {
  Session& doc = *doc_;
  if (s.first) {
    // A brush carried in from the other canvas keeps its paint, sample by sample.
    doc.begin_stroke(session_.player().pose_at(session_.player().t_begin()), session_.paint(), carried_paint_);
    carried_paint_ = false;
  }
  const double t = wall_now();
  const Int3 o0 = doc.sim().grid().window().origin();
  doc.step(session_.player(), s.step, s.events, s.pen_down_edge && session_.paint().reload_on_pen_down);
  for (const StrokeEvent& e : s.events)
    if (e.kind == StrokeEventKind::Dry) invalidate_all();
  step_times_.add(1e3 * (lap(times_.step, t) - t));
  // Paint changes only inside the active window (where it was and where it moved to).
  const Int3 o = doc.sim().grid().window().origin(), n = doc.sim().grid().window().dims();
  invalidate_rect(std::min(o.x, o0.x), std::min(o.y, o0.y), std::max(o.x, o0.x) + n.x, std::max(o.y, o0.y) + n.y);
  session_.step_done(s);
  paint_running_.store(doc.sim().paint_running(), std::memory_order_relaxed);
  // The pen events up to the step's end are in the paint now: they go with its next frame.
  const double consumed = wall_now();
  while (!pending_inputs_.empty() && pending_inputs_.front().session_t <= s.step.t) {
    frames_.input_consumed(pending_inputs_.front().wall_t, consumed);
    pending_inputs_.pop_front();
  }
  ++steps_;
  ++rate_steps_;
  step_ends_.push_back(wall_now());
}

void SimThread::finish_stroke() {
  if (doc_ && doc_->end_stroke()) Q_EMIT strokeFinished();
}

void SimThread::render(double min_interval) {
  if (!doc_) return;
  try {
    if (frames_.render(*doc_, min_interval)) Q_EMIT frameReady();
  } catch (const std::exception& e) {
    recover(e);  // the device failed between steps: the same as in one
  }
}

void SimThread::publish_status(bool force) {
  const double now = wall_now();
  if (!force && now - last_status_ < 0.5) return;
  std::lock_guard lk(status_mu_);
  const double span = now - rate_t0_;
  if (span > 0.25 && rate_steps_ > 0) status_.steps_per_s = rate_steps_ / span;
  if (rate_steps_ == 0) status_.steps_per_s = 0.0;
  rate_steps_ = 0;
  rate_t0_ = now;
  last_status_ = now;
  if (doc_) {
    const double med = sim().profiler().median_ms("sim.step");
    if (med > 0) status_.step_ms = med;
    sim().profiler().clear();  // bounded memory over a long session
    status_.particles = sim().particle_count();
  }
  // The real-time factor of the last second, while the simulation was behind all of it: a
  // simulation that caught up within it kept up, whatever its rate while it ran.
  while (!step_ends_.empty() && step_ends_.front() < now - 1.0) step_ends_.pop_front();
  status_.realtime_factor =
      !status_.idle && busy_since_ > 0.0 && now - busy_since_ >= 1.0 ? double(step_ends_.size()) * kStepDt : -1.0;
  status_.brush_samples = int64_t(config_.brush.bristles) * config_.brush.samples_per_bristle;
  status_.window = config_.window;
  status_.steps = steps_;
  status_.times = times_;
  status_.step_times = step_times_;
  const BrushPicture picture = frames_.brush_picture();
  status_.brush_ryb = {picture.mean_ryb.x, picture.mean_ryb.y, picture.mean_ryb.z};
  status_.brush_amount = picture.amount;
  status_.lag_s = session_.lag();
}

void SimThread::fail(const std::exception& e) {
  // The log (standard error) keeps the source location for a bug report; the painter is told
  // what went wrong in the studio's terms.
  std::fprintf(stderr, "wetbrush-studio: %s\n", e.what());
  Q_EMIT failed(QString::fromStdString(user_message(e)));
}

void SimThread::run() {
  for (;;) {
    std::deque<std::function<void(SimThread&)>> cmds;
    bool more = false;
    double t = wall_now();
    {
      std::unique_lock lk(in_mu_);
      more = busy_;
      in_cv_.wait(lk, [&] { return quit_ || !in_cmds_.empty() || more; });
      if (quit_) break;
      cmds.swap(in_cmds_);
      busy_ = true;
    }
    t = lap(times_.idle, t);
    for (auto& fn : cmds) {
      try {
        fn(*this);
      } catch (const std::exception& e) {
        fail(e);
      }
    }
    t = lap(times_.commands, t);
    // A few steps, then look at the inputs again: commands (undo, save) never wait long.
    const double t_start = wall_now();
    if (busy_since_ == 0.0) busy_since_ = t_start, rate_t0_ = t_start;
    int n = 0;
    try {
      SessionStep step;
      double tp = t_start;
      while (n < 64 && wall_now() - t_start < 0.05 && !failed_ && doc_) {
        const bool found = session_.next_step(step);
        lap(times_.player, tp);
        if (!found) break;
        run_step(step);
        tp = wall_now();
        ++n;
      }
      lap(times_.player, tp);
    } catch (const std::exception& e) {
      failed_ = true;
      {
        std::lock_guard lk(status_mu_);
        status_.error = user_message(e);
      }
      fail(e);
    }
    t = wall_now();
    const bool pending = !failed_ && step_available();
    t = lap(times_.player, t);
    if (!pending) {
      // Idle: the session time line is simulated up to its last sample; close the stroke.
      if (!session_.pen_down()) {
        try {
          finish_stroke();
        } catch (const std::exception& e) {
          recover(e);  // settling the stroke's paint failed: the stroke is not finished
        }
      }
      t = lap(times_.undo, t);
      render(0.0);
    } else {
      // Behind the pen: a frame a fifth of a second shows the painting going on, and the rest of
      // the thread's time goes to catching up (a frame costs about 2 ms; at 30 a second frames
      // held the simulation below real time: docs/STUDIO.md "Pen-to-paint latency").
      render(kBehindFrameInterval);
    }
    lap(times_.render, t);
    {
      std::lock_guard lk(status_mu_);
      status_.idle = !pending;
    }
    publish_status(!pending);
    {
      std::lock_guard lk(in_mu_);
      busy_ = pending;
      if (!pending) busy_since_ = 0.0;
    }
    idle_cv_.notify_all();
  }
  idle_cv_.notify_all();
}

}  // namespace wb::studio
