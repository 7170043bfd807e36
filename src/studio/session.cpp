#include "studio/session.h"

#include <algorithm>
#include <cmath>

namespace wb::studio {

void SessionTimeline::append(const ClockOutput& out) {
  std::lock_guard lk(mu_);
  for (const PenSample& s : out.samples) rec_.samples.push_back(s);
  for (const StrokeEvent& e : out.events) rec_.events.push_back(e);
}

void SessionTimeline::restart(Stroke header, bool from_blank) {
  {
    std::lock_guard lk(mu_);
    rec_ = std::move(header);
    rec_.samples.clear();
    rec_.events.clear();
  }
  chunk_start_ = 0;
  player_.reset();
  player_samples_ = 0;
  t_done_ = 0.0;
  started_ = false;
  next_event_ = 0;
  prev_contact_ = false;
  from_blank_ = from_blank;
}

Stroke SessionTimeline::recording() const {
  std::lock_guard lk(mu_);
  return rec_;
}

bool SessionTimeline::painted() const {
  return std::any_of(rec_.samples.begin(), rec_.samples.end(), [](const PenSample& s) { return s.down; });
}

double SessionTimeline::lag() const { return rec_.samples.empty() ? 0.0 : std::max(0.0, rec_.samples.back().t - t_done_); }

void SessionTimeline::rebuild_player() {
  Stroke chunk;
  {
    std::lock_guard lk(mu_);
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

bool SessionTimeline::has_step() {
  if (rec_.samples.empty()) return false;
  if (!player_ || player_samples_ != rec_.samples.size()) rebuild_player();
  const double horizon = rec_.samples.back().t;
  const double dt = rec_.dt;
  if (started_ && t_done_ + dt > horizon) return false;
  // A long press: put a knot on the last step boundary we can reach, between two pen-down
  // samples (where it changes no lift of a pen-up key), so the next player starts there.
  if (started_ && t_done_ - rec_.samples[chunk_start_].t >= 0.5) {
    const double T = std::floor(horizon / dt) * dt;
    const auto it = std::upper_bound(rec_.samples.begin(), rec_.samples.end(), T,
                                     [](double v, const PenSample& s) { return v < s.t; });
    const size_t j = size_t(it - rec_.samples.begin());  // first sample after T
    if (T > t_done_ && j > chunk_start_ + 1 && j < rec_.samples.size() && rec_.samples[j - 1].t < T &&
        rec_.samples[j - 1].down && rec_.samples[j].down) {
      PenSample knot = player_->pen_at(T);
      knot.t = T;
      knot.down = true;
      {
        std::lock_guard lk(mu_);
        rec_.samples.insert(rec_.samples.begin() + std::ptrdiff_t(j), knot);
      }
      rebuild_player();
    }
  }
  return player_->t_begin() + dt <= horizon;
}

bool SessionTimeline::next_step(SessionStep& out) {
  if (!has_step()) return false;
  bool found = false;
  while (player_->next(out.step))
    if (!started_ || out.step.t > t_done_) {
      found = true;
      break;
    }
  if (!found) return false;
  // Events fire in the first step ending at or after them. The pen-down edge is the session's:
  // a player rebuilt at a knot mid-stroke starts with the pen already down.
  const size_t first_event = next_event_;
  while (next_event_ < rec_.events.size() && rec_.events[next_event_].t <= out.step.t) ++next_event_;
  out.events = std::span<const StrokeEvent>(rec_.events.data() + first_event, next_event_ - first_event);
  out.pen_down_edge = out.step.pen_down && !prev_contact_;
  prev_contact_ = out.step.pen_down;
  out.first = !started_;
  started_ = true;
  out.from = player_->pen_at(out.step.t_begin);
  return true;
}

void SessionTimeline::step_done(const SessionStep& s) {
  t_done_ = s.step.t;
  // Knots: a sample on this step boundary lets the next player start here (cheap rebuilds).
  std::lock_guard lk(mu_);
  for (size_t j = rec_.samples.size(); j-- > chunk_start_ + 1;) {
    if (rec_.samples[j].t < t_done_) break;
    if (rec_.samples[j].t == t_done_) {
      chunk_start_ = j;
      player_.reset();
      break;
    }
  }
}

}  // namespace wb::studio
