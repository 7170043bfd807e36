#include "studio/pen_clock.h"

#include <chrono>

#include <algorithm>
#include <cmath>

namespace wb::studio {

double wall_now() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

double ceil_to(double t, double q) { return std::ceil(t / q - 1e-9) * q; }

PenSample PenClock::sample(const PenInput& p, double t, bool down) const {
  PenSample s;
  s.t = t;
  s.x = std::clamp(p.x, 0.f, float(w_));
  s.y = std::clamp(p.y, 0.f, float(h_));
  s.pressure = down ? std::clamp(p.pressure, 0.f, 1.f) : 0.f;
  s.tilt_x = p.tilt_x;
  s.tilt_y = p.tilt_y;
  s.twist = p.twist;
  s.down = down;
  return s;
}

double PenClock::stamp(double t) {
  // Session time of an input during a press: time since the press on the session line,
  // quantised, and always after the previous sample.
  const double s = press_session_t_ + std::floor((t - press_t_) / kTimeQuantum) * kTimeQuantum;
  return std::max(s, last_t_ + kTimeQuantum);
}

void PenClock::push(ClockOutput& out, const PenSample& s) {
  out.samples.push_back(s);
  last_t_ = s.t;
  last_ = s;
  any_ = true;
}

ClockOutput PenClock::press(const PenInput& p, double t, double arrival) {
  ClockOutput out;
  if (down_) return move(p, t, arrival);
  // The brush hovers above the new spot kLiftGap before touching, kPressLead after the previous
  // stroke's last (lifted, step-aligned) sample: the rest of the gap came with the release. The
  // first sample of a recording is the hover, kLeadIn into it.
  const double s = (any_ ? last_t_ + kTravel : kLeadIn) + kLiftGap;
  push(out, sample(p, s - kLiftGap, false));
  push(out, sample(p, s, true));
  out.input = PenEventTime{s, t};
  down_ = true;
  press_session_t_ = s;
  press_t_ = last_event_t_ = t;
  last_arrival_ = last_input_ = arrival;
  return out;
}

ClockOutput PenClock::move(const PenInput& p, double t, double arrival) {
  ClockOutput out;
  if (!down_) return out;
  last_event_t_ = t;
  last_arrival_ = last_input_ = arrival;
  push(out, sample(p, stamp(t), true));
  out.input = PenEventTime{last_t_, t};
  return out;
}

ClockOutput PenClock::hold(double now) {
  ClockOutput out;
  // Still once nothing came for kHoldAfter; then repeated a step apart until the pen moves.
  if (!down_ || now - last_input_ < kHoldAfter || now - last_arrival_ < kStepDt) return out;
  // Held since the last sample for as long as nothing has come.
  last_event_t_ += now - last_arrival_;
  last_arrival_ = now;
  PenSample s = last_;
  s.t = stamp(last_event_t_);
  push(out, s);
  return out;
}

ClockOutput PenClock::release(const PenInput& p, double t) {
  ClockOutput out;
  if (!down_) return out;
  push(out, sample(p, stamp(t), true));
  out.input = PenEventTime{last_t_, t};
  // Lifted kLiftGap later, then held still there for the gap but the next press's lead, up to a
  // step boundary: the simulation may run every step up to that sample without knowing what
  // comes next.
  const double up = last_t_ + kLiftGap;
  push(out, sample(p, up, false));
  push(out, sample(p, ceil_to(up + kStepDt + (kStrokeGap - kPressLead), kStepDt), false));
  down_ = false;
  return out;
}

ClockOutput PenClock::air(double now) {
  ClockOutput out;
  // The time line ends on a lifted sample on a step boundary (release, event): it goes on by the
  // steps the wall clock has run since the last sample, with the brush held there. A few at most:
  // the first call after a release comes once the simulation has run the gap, whose steps already
  // stand for the wall time since the last sample's arrival, and the caller asks again once the
  // simulation has caught up. Time between strokes is then the gap and as long as the paint ran.
  const int n = std::min(4, int((now - last_arrival_) / kStepDt));
  if (down_ || !any_ || n < 1) return out;
  last_arrival_ = now;
  for (int k = 0; k < n; ++k) {
    PenSample s = last_;
    s.t = last_t_ + kStepDt;
    push(out, s);
  }
  return out;
}

ClockOutput PenClock::event(StrokeEvent e) {
  ClockOutput out;
  if (down_) return out;  // the caller queues palette actions until the pen is up
  PenInput at;
  if (any_) {
    at = PenInput{last_.x, last_.y, 0.f, last_.tilt_x, last_.tilt_y, last_.twist};
  } else {
    at.x = float(w_) * 0.5f;
    at.y = float(h_) * 0.5f;
  }
  // Before the first stroke: an anchor sample at the start of the line (the lead-in
  // then ends there); afterwards the event sits inside the next step, closed by a
  // lifted sample on that step's end.
  const double t0 = any_ ? last_t_ : kLeadIn;
  if (!any_) push(out, sample(at, t0, false));
  e.t = t0 + 0.5 * kStepDt;
  out.events.push_back(e);
  push(out, sample(at, t0 + kStepDt, false));
  return out;
}

}  // namespace wb::studio
