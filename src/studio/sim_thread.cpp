#include "studio/sim_thread.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "core/color/ryb.h"
#include "core/exec/error.h"
#include "core/sim/replay.h"

namespace wb::studio {
namespace {

double wall_now() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

/// Adds the time since `since` to `bucket`; returns now.
double lap(double& bucket, double since) {
  const double now = wall_now();
  bucket += now - since;
  return now;
}

/// Cells around the pen that one step may change: the active window, centred near the brush's
/// footprint (the bristles' reach) and snapped to the grid's window snap.
int step_reach(const SimConfig& c) {
  return int(c.brush.length + std::max(c.brush.width, c.brush.thickness)) + std::max(c.window.x, c.window.y) / 2 +
         c.params.grid.window_snap + 2;
}

}  // namespace

QualityPreset QualityPreset::cpu() {
  QualityPreset p;
  p.name = "CPU (light)";
  p.bristles = 80;
  p.samples_per_bristle = 128;
  p.canvas_width = 1200;
  p.canvas_height = 900;
  p.canvas_depth = 32;
  p.ao_rays = 12;
  p.window_xy = 64;
  p.window_z = 16;
  return p;
}

QualityPreset QualityPreset::gpu() {
  QualityPreset p;
  p.name = "GPU (paper)";
  p.bristles = 400;
  p.samples_per_bristle = 128;
  p.canvas_width = 4096;
  p.canvas_height = 4096;
  p.canvas_depth = 64;
  p.ao_rays = 64;
  return p;
}

QualityPreset QualityPreset::tiny() {
  QualityPreset p;
  p.name = "tiny";
  p.bristles = 40;  // the fewest a brush file accepts
  p.brush_length = 16.f;
  p.brush_width = 8.f;
  p.samples_per_bristle = 24;  // gap below one cell along the longest bristle (16 x 1.16)
  p.canvas_width = 160;
  p.canvas_height = 120;
  p.canvas_depth = 16;
  p.ao_rays = 4;
  p.window_xy = 48;  // particles within D0's floor, about 8.6 cells, of the bristles (Simulator::place_window)
  p.window_z = 8;
  return p;
}

QualityPreset QualityPreset::from_name(const std::string& name, const Device& d) {
  if (name == "auto") return for_device(d);
  if (name == "cpu") return cpu();
  if (name == "gpu") return gpu();
  if (name == "tiny") return tiny();
  WB_THROW("unknown quality preset '" + name + "' (valid: auto, cpu, gpu, tiny)");
}

BrushSpec QualityPreset::start_brush() const {
  BrushSpec b = default_brush(BrushShape::Round);
  b.bristles = bristles;
  b.samples_per_bristle = samples_per_bristle;
  if (brush_length > 0.f) b.length = brush_length;
  if (brush_width > 0.f) b.width = b.thickness = brush_width;
  return b;
}

SimThread::SimThread(const SimConfig& config, const RenderParams& render, QObject* parent)
    : QObject(parent), config_(config), renderer_(config.device) {
  renderer_.params() = render;
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
    std::lock_guard lk(self.rec_mu_);
    for (const PenSample& s : out.samples) self.rec_.samples.push_back(s);
    for (const StrokeEvent& e : out.events) self.rec_.events.push_back(e);
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

Stroke SimThread::recording() const {
  std::lock_guard lk(rec_mu_);
  return rec_;
}

SimStatus SimThread::status() const {
  std::lock_guard lk(status_mu_);
  return status_;
}

QRect SimThread::take_frame(QImage& canvas) { return frames_.take(canvas); }

// --- simulation thread ------------------------------------------------------------------

void SimThread::rebuild(const SimConfig& config, bool keep_canvas) {
  // Finish the old time line on the old simulator first.
  if (sim_ && !failed_) drain();
  finish_stroke();
  std::unique_ptr<Simulator> old = std::move(sim_);
  const bool same_dims = old && old->canvas().dims() == config.canvas;
  config_ = config;
  BrushPose rest;
  rest.position = Vec3(config.canvas.width * 0.5f, config.canvas.height * 0.5f, config.brush.length * 1.5f);
  sim_ = std::make_unique<Simulator>(config_, rest);
  // Nothing painted in this recording: a new one from the blank (primed) canvas is the same.
  bool painted = false;
  {
    std::lock_guard lk(rec_mu_);
    for (const PenSample& s : rec_.samples) painted |= s.down;
  }
  if (keep_canvas && same_dims) {
    // The paint that was in flight comes too; the old simulator goes, so it settles for good,
    // and its canvas is copied on the device.
    old->settle();
    write_canvas([&](TileStore& canvas) {
      if (old->device() == config.device) {
        canvas.copy_from(old->canvas());
      } else {
        for (int id : old->canvas().allocated_tile_ids()) canvas.write_tile(old->canvas().read_tile(id));
      }
    });
  } else {
    write_canvas([](TileStore&) {});
  }
  old.reset();
  restart_recording(recording_from_blank_.load() && !(keep_canvas && same_dims && painted));
  if (!frames_.ready() || !same_dims) frames_.reset(config.canvas);
  {
    std::lock_guard lk(status_mu_);
    status_.device = config.device.to_string();
  }
  invalidate_all();
  render(true);
}

void SimThread::restart_recording(bool from_blank) {
  // The old time line is simulated to its end first, and its open stroke closed.
  if (!failed_) drain();
  finish_stroke();
  std::lock_guard lk(rec_mu_);
  rec_ = Stroke{};
  rec_.canvas = config_.canvas;
  rec_.brush = config_.brush;
  rec_.paint = paint_;
  rec_.ground = ground_;
  rec_.paint.reload_on_pen_down = false;  // the studio's brush stays dirty between strokes
  rec_.paper_rgb = std::array<float, 3>{renderer_.params().paper_rgb.x, renderer_.params().paper_rgb.y,
                                        renderer_.params().paper_rgb.z};
  rec_.window = std::array<int, 3>{config_.window.x, config_.window.y, config_.window.z};  // the replay's window
  rec_.dt = kStepDt;
  rec_.lead_in = kLeadIn;
  rec_.lead_out = 0.0;
  rec_.source = "studio session";
  chunk_start_ = 0;
  player_.reset();
  player_samples_ = 0;
  t_done_ = 0.0;
  started_ = false;
  next_event_ = 0;
  prev_contact_ = false;
  recording_from_blank_ = from_blank;
}

void SimThread::prime(const CanvasGround& g) {
  sim_->lay_ground(g, rgb_to_ryb(renderer_.params().paper_rgb));
  ground_ = g;
  undo_rec_.reset();
  stroke_open_ = false;
  invalidate_all();
}

void SimThread::write_canvas(const std::function<void(TileStore&)>& write) {
  if (!sim_) return;
  sim_->replace_canvas(write);
  undo_rec_.reset();
  stroke_open_ = false;
}

void SimThread::invalidate_all() { frames_.invalidate_all(); }

void SimThread::invalidate_rect(int x0, int y0, int x1, int y1) { frames_.invalidate_rect(x0, y0, x1, y1); }

BrushPicture SimThread::brush_picture() const { return frames_.brush_picture(); }

Image SimThread::canvas_image() { return sim_ ? frames_.canvas_image(*sim_) : Image{}; }

void SimThread::render_oblique(float elevation_deg, int max_width) {
  if (!sim_) return;
  const CanvasDims d = sim_->canvas().dims();
  const float zoom = std::min(1.f, float(max_width) / float(d.width));
  const Image img = renderer_.render(sim_->canvas(), Camera::oblique(d, elevation_deg, zoom), sim_->live_window());
  QImage q(img.width, img.height, QImage::Format_RGBA8888);
  for (int y = 0; y < img.height; ++y) std::memcpy(q.scanLine(y), img.at(0, y), size_t(img.width) * 4);
  Q_EMIT obliqueReady(q);
}

void SimThread::drain() {
  PlayerStep step;
  while (step_available()) {
    bool found = false;
    while (player_->next(step))
      if (!started_ || step.t > t_done_) {
        found = true;
        break;
      }
    if (!found) break;
    run_step(step);
  }
}

void SimThread::rebuild_player() {
  Stroke chunk;
  {
    std::lock_guard lk(rec_mu_);
    chunk.canvas = rec_.canvas;
    chunk.brush = rec_.brush;
    chunk.paint = rec_.paint;
    chunk.dt = rec_.dt;
    chunk.max_move_per_substep = rec_.max_move_per_substep;
    chunk.max_substeps = rec_.max_substeps;
    chunk.samples.assign(rec_.samples.begin() + std::ptrdiff_t(chunk_start_), rec_.samples.end());
    player_samples_ = rec_.samples.size();
  }
  // The first chunk has the recording's lead-in; later ones start at a knot on a step
  // boundary, where the full recording's keys and these agree exactly.
  chunk.lead_in = chunk_start_ == 0 ? rec_.lead_in : 0.0;
  chunk.lead_out = 0.0;
  chunk.source = "studio session";
  player_ = std::make_unique<StrokePlayer>(std::move(chunk));
}

bool SimThread::step_available() {
  if (failed_ || !sim_ || rec_.samples.empty()) return false;
  if (!player_ || player_samples_ != rec_.samples.size()) rebuild_player();
  const double horizon = rec_.samples.back().t;
  if (started_ && t_done_ + kStepDt > horizon) return false;
  // A long press: put a knot on the last step boundary we can reach, between two pen-down
  // samples (where it changes no lift of a pen-up key), so the next player starts there.
  if (started_ && t_done_ - rec_.samples[chunk_start_].t >= 0.5) {
    const double T = std::floor(horizon / kStepDt) * kStepDt;
    const auto it = std::upper_bound(rec_.samples.begin(), rec_.samples.end(), T,
                                     [](double v, const PenSample& s) { return v < s.t; });
    const size_t j = size_t(it - rec_.samples.begin());  // first sample after T
    if (T > t_done_ && j > chunk_start_ + 1 && j < rec_.samples.size() && rec_.samples[j - 1].t < T &&
        rec_.samples[j - 1].down && rec_.samples[j].down) {
      PenSample knot = player_->pen_at(T);
      knot.t = T;
      knot.down = true;
      {
        std::lock_guard lk(rec_mu_);
        rec_.samples.insert(rec_.samples.begin() + std::ptrdiff_t(j), knot);
      }
      rebuild_player();
    }
  }
  return player_->t_begin() + kStepDt <= horizon;
}

void SimThread::run_step(const PlayerStep& step) {
  Simulator& sim = *sim_;
  if (!started_) {
    sim.reset_brush(player_->pose_at(player_->t_begin()));
    sim.load_paint(rec_.paint);
    started_ = true;
  }
  // Events fire in the first step ending at or after them. The pen-down edge is the session's:
  // a player rebuilt at a knot mid-stroke starts with the pen already down.
  const size_t first_event = next_event_;
  while (next_event_ < rec_.events.size() && rec_.events[next_event_].t <= step.t) ++next_event_;
  const std::span<const StrokeEvent> events(rec_.events.data() + first_event, next_event_ - first_event);
  const bool edge = step.pen_down && !prev_contact_;
  prev_contact_ = step.pen_down;

  // Undo: capture the tiles this step may touch before it runs.
  const int reach = step_reach(config_);
  const PenSample a = player_->pen_at(step.t_begin), b = step.pen;
  const int x0 = int(std::min(a.x, b.x)) - reach, x1 = int(std::max(a.x, b.x)) + reach;
  const int y0 = int(std::min(a.y, b.y)) - reach, y1 = int(std::max(a.y, b.y)) + reach;
  // Every step belongs to the undo record of the stroke it leads to: the steps between two
  // strokes (the lifted brush moving on, paint in flight landing) change tiles too.
  stroke_open_ = true;
  double t = wall_now();
  undo_rec_.capture_rect(sim.canvas(), x0, y0, x1, y1);
  t = lap(times_.undo, t);
  const Int3 o0 = sim.live_window()->origin();
  drive_step(sim, *player_, step, events, edge && rec_.paint.reload_on_pen_down, poses_);
  for (const StrokeEvent& e : events)
    if (e.kind == StrokeEventKind::Dry) invalidate_all();
  lap(times_.step, t);
  // Paint changes only inside the active window (where it was and where it moved to).
  const Int3 o = sim.live_window()->origin(), n = sim.live_window()->dims();
  invalidate_rect(std::min(o.x, o0.x), std::min(o.y, o0.y), std::max(o.x, o0.x) + n.x, std::max(o.y, o0.y) + n.y);
  t_done_ = step.t;
  ++steps_;
  ++rate_steps_;

  // Knots: a sample on this step boundary lets the next player start here (cheap rebuilds).
  std::lock_guard lk(rec_mu_);
  for (size_t j = rec_.samples.size(); j-- > chunk_start_ + 1;) {
    if (rec_.samples[j].t < t_done_) break;
    if (rec_.samples[j].t == t_done_) {
      chunk_start_ = j;
      player_.reset();
      break;
    }
  }
}


void SimThread::finish_stroke() {
  if (!stroke_open_ || !sim_) return;
  stroke_open_ = false;
  // The record holds the canvas with its paint at rest, before and after. Paint still in
  // flight lands during the next steps, under the window: those tiles start the next record
  // as they are at rest now, so that its undo returns to exactly this canvas.
  auto diff = std::make_shared<TileDiff>();
  const Int3 o = sim_->live_window()->origin(), n = sim_->live_window()->dims();
  sim_->with_settled_canvas([&](TileStore& c) {
    *diff = undo_rec_.finish(c);
    undo_rec_.capture_rect(c, o.x, o.y, o.x + n.x, o.y + n.y);
  });
  if (!diff->empty()) Q_EMIT strokeFinished(diff);
}

void SimThread::render(bool force) {
  if (sim_ && frames_.render(*sim_, force)) Q_EMIT frameReady();
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
  if (sim_) {
    const double med = sim_->profiler().median_ms("sim.step");
    if (med > 0) status_.step_ms = med;
    sim_->profiler().clear();  // bounded memory over a long session
    status_.particles = sim_->particle_count();
  }
  status_.steps = steps_;
  status_.times = times_;
  const BrushPicture picture = frames_.brush_picture();
  status_.brush_ryb = {picture.mean_ryb.x, picture.mean_ryb.y, picture.mean_ryb.z};
  status_.brush_amount = picture.amount;
  status_.lag_s = rec_.samples.empty() ? 0.0 : std::max(0.0, rec_.samples.back().t - t_done_);
}

void SimThread::run() {
  double busy_since = 0.0;
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
        Q_EMIT failed(QString::fromStdString(user_message(e)));
      }
    }
    t = lap(times_.commands, t);
    // A few steps, then look at the inputs again: commands (undo, save) never wait long.
    const double t_start = wall_now();
    if (busy_since == 0.0) busy_since = t_start, rate_t0_ = t_start;
    int n = 0;
    try {
      PlayerStep step;
      double tp = t_start;
      while (n < 64 && wall_now() - t_start < 0.05 && step_available()) {
        bool found = false;
        while (player_->next(step)) {
          if (!started_ || step.t > t_done_) {
            found = true;
            break;
          }
        }
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
      Q_EMIT failed(QString::fromStdString(user_message(e)));
    }
    t = wall_now();
    const bool pending = !failed_ && step_available();
    t = lap(times_.player, t);
    if (!pending) {
      // Idle: the session time line is simulated up to its last sample; close the stroke.
      if (!prev_contact_) {
        try {
          finish_stroke();
        } catch (const std::exception& e) {
          Q_EMIT failed(QString::fromStdString(user_message(e)));
        }
      }
      t = lap(times_.undo, t);
      render(true);
    } else {
      render(false);
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
      if (!pending) busy_since = 0.0;
    }
    idle_cv_.notify_all();
  }
  idle_cv_.notify_all();
}

}  // namespace wb::studio
