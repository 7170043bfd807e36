// Stroke input: StrokePlayer timeline, interpolation, sub-steps, pen edges and events.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core/exec/error.h"
#include "core/io/pen_pose.h"
#include "core/io/stroke_player.h"

namespace wb {
namespace {

PenSample pen(double t, float x, float y, float p, bool down = true, float tw = 0, float tx = 0) {
  PenSample s;
  s.t = t;
  s.x = x;
  s.y = y;
  s.pressure = p;
  s.down = down;
  s.twist = tw;
  s.tilt_x = tx;
  return s;
}

Stroke make_stroke(std::vector<PenSample> samples) {
  Stroke s;
  s.canvas = {1024, 1024, 64};
  s.brush = default_brush(BrushShape::Flat);
  s.samples = std::move(samples);
  s.source = "test";
  return s;
}

/// Same reference points as the player: ferrule centre, ferrule edge midpoints, rest tip.
std::vector<Vec3> ref_points(const BrushPose& p, const BrushSpec& b) {
  const Vec3 ex = p.rotation.col(0), ey = p.rotation.col(1), ez = p.rotation.col(2);
  return {p.position, p.position + ex * (0.5f * b.width), p.position - ex * (0.5f * b.width),
          p.position + ey * (0.5f * b.thickness), p.position - ey * (0.5f * b.thickness), p.position - ez * b.length};
}

TEST(StrokePlayer, StepCountIsCeilOfDuration) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.2), pen(1.0, 200, 100, 0.2)});
  s.dt = 0.02;
  s.lead_in = 0.2;
  s.lead_out = 0.17;
  StrokePlayer player(s);
  EXPECT_DOUBLE_EQ(player.t_begin(), -0.2);
  EXPECT_DOUBLE_EQ(player.t_end(), 1.17);
  EXPECT_EQ(player.step_count(), int64_t(std::ceil(1.37 / 0.02)));  // 69
  PlayerStep st;
  int64_t n = 0;
  double last_t = 0;
  while (player.next(st)) {
    EXPECT_EQ(st.index, n);
    EXPECT_NEAR(st.t - st.t_begin, 0.02, 1e-12);
    last_t = st.t;
    ++n;
  }
  EXPECT_EQ(n, player.step_count());
  EXPECT_GE(last_t, player.t_end());
  EXPECT_LT(last_t - 0.02, player.t_end());

  // An exact multiple does not gain a step to rounding: 1.5 s at 1/60 s is 90 steps.
  Stroke e = make_stroke({pen(0.0, 100, 100, 0.2), pen(1.0, 200, 100, 0.2)});
  EXPECT_EQ(StrokePlayer(e).step_count(), 90);
}

TEST(StrokePlayer, PosesExactAtSampleTimes) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.0), pen(0.1, 150, 120, 0.6, true, 40, 20),
                          pen(0.25, 170, 160, 0.9, true, 350, -30), pen(0.3, 180, 160, 0, false, 10)});
  StrokePlayer player(s);
  for (const PenSample& p : s.samples) {
    const BrushPose a = player.pose_at(p.t);
    // The pen-up sample is 0.05 s after a contact: half the lift (kLiftTime = 0.1 s).
    const BrushPose b = p.down ? pose_from_pen(p, s.brush) : pose_from_pen(p, -0.5f, s.brush);
    EXPECT_EQ(a.position.x, b.position.x);
    EXPECT_EQ(a.position.y, b.position.y);
    EXPECT_EQ(a.position.z, b.position.z);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_EQ(a.rotation.r[i][j], b.rotation.r[i][j]);
  }
}

TEST(StrokePlayer, InterpolatesLinearlyAndTwistTheShortWay) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.2, true, 350, 10), pen(1.0, 200, 300, 0.6, true, 10, 30)});
  StrokePlayer player(s);
  const PenSample m = player.pen_at(0.5);
  EXPECT_NEAR(m.x, 150.f, 1e-4f);
  EXPECT_NEAR(m.y, 200.f, 1e-4f);
  EXPECT_NEAR(m.pressure, 0.4f, 1e-6f);
  EXPECT_NEAR(m.tilt_x, 20.f, 1e-5f);
  EXPECT_NEAR(std::fmod(m.twist + 360.f, 360.f), 0.f, 1e-4f);  // through 0, not through 180
  const PenSample q = player.pen_at(0.25);
  EXPECT_NEAR(q.twist, 355.f, 1e-4f);
}

TEST(StrokePlayer, LeadInAndOutHoldTheBrushInTheAir) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.5), pen(0.5, 200, 100, 0.5)});
  StrokePlayer player(s);
  EXPECT_FLOAT_EQ(player.elevation_at(player.t_begin()), -1.f);
  EXPECT_FLOAT_EQ(player.elevation_at(player.t_end()), -1.f);
  const BrushPose a = player.pose_at(player.t_begin());
  EXPECT_FLOAT_EQ(a.position.x, 100.f);
  EXPECT_NEAR(a.position.z, s.brush.length * (1.f + kPenUpLift), 1e-3f);
  const BrushPose z = player.pose_at(player.t_end() + 10.0);  // clamped beyond the end
  EXPECT_FLOAT_EQ(z.position.x, 200.f);
  // Descending during the lead-in.
  EXPECT_GT(player.pose_at(-0.2).position.z, player.pose_at(-0.1).position.z);
}

TEST(StrokePlayer, StaysLiftedBetweenPenUpSamples) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.5), pen(0.1, 120, 100, 0.0, false),
                          pen(0.5, 400, 300, 0.3, false), pen(0.6, 420, 300, 0.5)});
  StrokePlayer player(s);
  for (double t = 0.1; t <= 0.5; t += 0.05) EXPECT_FLOAT_EQ(player.elevation_at(t), -1.f) << t;
}

TEST(StrokePlayer, HoverNearContactIsPartlyLifted) {
  // Hover events every 5 ms up to a contact, as a tablet reports them.
  std::vector<PenSample> v;
  for (int i = 0; i < 40; ++i) v.push_back(pen(0.005 * i, 100 + i, 100, 0, false));
  v.push_back(pen(0.2, 140, 100, 0.02));  // touches lightly, then presses in
  v.push_back(pen(0.3, 160, 100, 0.3));
  Stroke s = make_stroke(v);
  StrokePlayer player(s);
  EXPECT_FLOAT_EQ(player.elevation_at(0.0), -1.f);     // 0.2 s from the contact
  EXPECT_FLOAT_EQ(player.elevation_at(0.195), -0.05f);  // 5 ms before it
  EXPECT_NEAR(player.elevation_at(0.15), -0.5f, 1e-6f);
  PlayerStep st;
  int max_n = 0;
  while (player.next(st)) max_n = std::max(max_n, st.substeps);
  // Full lift (half the 90-cell length) over kLiftTime: under 8 cells per 1/60 s step.
  EXPECT_LE(max_n, 8);
}

TEST(StrokePlayer, APauseIsSpentInTheAirAndThePenLandsInTheLiftTime) {
  // Lifted at 0.5 s, down again at 60.5 s with no sample between (a recording's pause): the pen
  // rises in kLiftTime, stays fully lifted and comes down in the last half kLiftTime (above the
  // contact by then), not over the minute.
  Stroke s = make_stroke({pen(0.0, 300, 500, 0.4), pen(0.5, 350, 500, 0.4), pen(0.51, 351, 500, 0, false),
                          pen(60.5, 600, 500, 0.4), pen(61.0, 650, 500, 0.4)});
  StrokePlayer player(s);
  EXPECT_FLOAT_EQ(player.elevation_at(0.51 + kLiftTime), -1.f);
  EXPECT_FLOAT_EQ(player.elevation_at(30.0), -1.f);
  EXPECT_FLOAT_EQ(player.elevation_at(60.5 - kLiftTime), -1.f);
  EXPECT_FLOAT_EQ(player.elevation_at(60.5 - 0.5 * kLiftTime), -1.f);
  EXPECT_GT(player.elevation_at(60.5 - 0.25 * kLiftTime), -1.f);
  EXPECT_NEAR(player.pen_at(30.0).x, 351.f + (600.f - 351.f) * float((30.0 - 0.51) / (60.5 - 0.51)), 1e-3f)
      << "the path between the samples is the straight one";
  // The lead-in keeps its own descent (0.25 s from full lift).
  EXPECT_GT(player.elevation_at(-0.2), -1.f);
  EXPECT_LT(player.elevation_at(-0.2), -0.5f);

  // The air ahead: none while the pen is down; from the first step in the air, up to the
  // margin before the pen starts down at 60.5 - kLiftTime / 2.
  PlayerStep st;
  int64_t in_air = -1;
  while (player.next(st)) {
    const int64_t ahead = player.air_steps_ahead(0.25);
    if (st.pen_down) EXPECT_EQ(ahead, 0) << "step " << st.index;
    if (!st.pen_down && st.t > 1.0) {
      in_air = ahead;
      const double until = st.t + double(ahead) * s.dt;
      EXPECT_LE(until, 60.5 - 0.5 * kLiftTime - 0.25 + 1e-9);
      EXPECT_GT(until, 60.5 - 0.5 * kLiftTime - 0.25 - s.dt - 1e-9);
      player.skip(ahead);
      PlayerStep next;
      ASSERT_TRUE(player.next(next));
      EXPECT_FALSE(next.pen_down) << "the margin is played in the air";
      EXPECT_NEAR(next.t, until + s.dt, 1e-9);
      break;
    }
  }
  EXPECT_GT(in_air, 3000);
  while (player.next(st)) EXPECT_EQ(player.air_steps_ahead(0.25), 0) << "lead-out: the last steps are played";
}

TEST(StrokePlayer, APenLandingFromAfarArrivesThenComesDown) {
  // The last hover sample 200 cells and 0.1 s from the contact (a tablet's fast approach): the
  // brush keeps the hover's height until it is above the contact, then comes down onto it.
  Stroke s = make_stroke({pen(0.0, 100, 128, 0, false), pen(0.1, 300, 128, 0.5), pen(0.4, 400, 128, 0.5)});
  StrokePlayer player(s);
  const float hover = player.elevation_at(0.0);
  EXPECT_FLOAT_EQ(hover, -1.f);
  for (double t = 0.0; t < 0.1; t += 0.002) {
    const float x = player.pen_at(t).x, e = player.elevation_at(t);
    if (x < 299.9f) EXPECT_FLOAT_EQ(e, hover) << "t " << t << ": the brush comes down before it arrives (x " << x << ")";
  }
  EXPECT_NEAR(player.pen_at(0.05).x, 300.f, 1e-3f) << "above the contact half-way";
  EXPECT_NEAR(player.elevation_at(0.075), -0.25f, 1e-5f) << "coming down: from the hover to the press";
  EXPECT_FLOAT_EQ(player.elevation_at(0.1), 0.5f);
  // A hover just above the contact (5 ms events) comes down as before, within its 5 ms.
  Stroke near = make_stroke({pen(0.0, 100, 128, 0, false), pen(0.005, 101, 128, 0.2)});
  StrokePlayer p2(near);
  EXPECT_FLOAT_EQ(p2.elevation_at(0.0), -0.05f);
  EXPECT_GE(p2.elevation_at(0.005), 0.f);
}

TEST(StrokePlayer, AnEventEndsTheAirAhead) {
  Stroke s = make_stroke({pen(0.0, 300, 500, 0.4), pen(0.5, 350, 500, 0.4), pen(0.51, 351, 500, 0, false),
                          pen(20.5, 600, 500, 0.4)});
  StrokeEvent dip;
  dip.t = 10.0;
  dip.kind = StrokeEventKind::Dip;
  s.events = {dip};
  StrokePlayer player(s);
  PlayerStep st;
  while (player.next(st) && (st.pen_down || st.t < 1.0)) {}
  EXPECT_LE(st.t + double(player.air_steps_ahead(0.25)) * s.dt, 10.0);
}

TEST(StrokePlayer, SubstepsBoundMovement) {
  // 300 cells in 0.1 s with a twist: 50 cells per 1/60 s step.
  Stroke s = make_stroke({pen(0.0, 300, 500, 0.3), pen(0.1, 600, 500, 0.6, true, 90, 20),
                          pen(0.4, 610, 520, 0.5, true, 100, 20)});
  s.max_move_per_substep = 2.f;
  StrokePlayer player(s);
  PlayerStep st;
  int max_n = 0;
  while (player.next(st)) {
    ASSERT_GE(st.substeps, 1);
    ASSERT_LE(st.substeps, s.max_substeps);
    max_n = std::max(max_n, st.substeps);
    float worst = 0.f;
    for (int k = 1; k <= st.substeps; ++k) {
      const auto a = ref_points(player.pose_at(StrokePlayer::substep_time(st, k - 1)), s.brush);
      const auto b = ref_points(player.pose_at(StrokePlayer::substep_time(st, k)), s.brush);
      for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, length(b[i] - a[i]));
    }
    EXPECT_NEAR(worst, st.max_move, 1e-4f);
    if (st.substeps < s.max_substeps) {
      EXPECT_LE(worst, s.max_move_per_substep + 1e-4f) << "step " << st.index;
    }
    // Fewer sub-steps would break the bound (n is not needlessly large), up to one for rounding.
    if (st.substeps > 2) {
      EXPECT_GT(worst * st.substeps, s.max_move_per_substep * (st.substeps - 2));
    }
  }
  EXPECT_GE(max_n, 25);  // 50 cells / 2 cells

  // A resting brush needs one sub-step.
  Stroke r = make_stroke({pen(0.0, 300, 500, 0.3), pen(1.0, 300, 500, 0.3)});
  r.lead_in = r.lead_out = 0;
  StrokePlayer rest(r);
  while (rest.next(st)) EXPECT_EQ(st.substeps, 1);

  // The cap holds, and the step reports the larger per-sub-step move.
  Stroke f = make_stroke({pen(0.0, 10, 500, 0.3), pen(0.05, 1000, 500, 0.3)});
  f.max_substeps = 4;
  StrokePlayer fast(f);
  bool capped = false;
  while (fast.next(st)) {
    EXPECT_LE(st.substeps, 4);
    if (st.substeps == 4 && st.max_move > 2.f) capped = true;
  }
  EXPECT_TRUE(capped);
}

TEST(StrokePlayer, ALiftedTravelTakesABrushLengthASubstep) {
  // Two strokes 400 cells apart, the pen carried between them lifted in 0.05 s (8 cells a
  // millisecond, 133 a step): the lifted steps take a sub-step per brush length of the travel,
  // the steps in contact or coming down the stroke's bound.
  Stroke s = make_stroke({pen(0.0, 100, 500, 0.4), pen(0.2, 150, 500, 0.4), pen(0.3, 150, 500, 0, false),
                          pen(0.35, 550, 500, 0, false), pen(0.5, 550, 500, 0.4), pen(0.7, 600, 500, 0.4)});
  s.max_move_per_substep = 2.f;
  StrokePlayer player(s);
  PlayerStep st;
  int lifted_steps = 0, max_lifted = 0;
  while (player.next(st)) {
    bool lifted = player.elevation_at(st.t_begin) <= -1.f && st.elevation <= -1.f;
    for (int k = 1; k < 8; ++k) lifted = lifted && player.elevation_at(st.t_begin + st.dt * k / 8) <= -1.f;
    if (lifted) {
      ++lifted_steps;
      max_lifted = std::max(max_lifted, st.substeps);
      EXPECT_LE(st.max_move, s.brush.length + 1e-3f) << "step " << st.index;
      if (st.substeps > 1) {  // fewer would break the bound
        EXPECT_GT(st.max_move * st.substeps, s.brush.length * (st.substeps - 1)) << "step " << st.index;
      }
    } else if (st.substeps < s.max_substeps) {
      EXPECT_LE(st.max_move, s.max_move_per_substep + 1e-4f) << "step " << st.index;
    }
  }
  EXPECT_GE(lifted_steps, 3);
  EXPECT_GE(max_lifted, 2);                                            // 133 cells a step
  EXPECT_LE(max_lifted, int(std::ceil(140.f / s.brush.length)) + 1);  // not 133 / 2
}

TEST(StrokePlayer, PenDownEdgesFire) {
  // down, up (lifted gap), down again.
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.4), pen(0.3, 200, 100, 0.4), pen(0.4, 220, 100, 0, false),
                          pen(0.8, 400, 100, 0, false), pen(0.9, 420, 100, 0.4), pen(1.2, 500, 100, 0.4)});
  StrokePlayer player(s);
  PlayerStep st;
  std::vector<PlayerStep> down_edges, up_edges;
  bool prev = false;
  while (player.next(st)) {
    EXPECT_EQ(st.pen_down_edge, st.pen_down && !prev);
    EXPECT_EQ(st.pen_up_edge, !st.pen_down && prev);
    prev = st.pen_down;
    if (st.pen_down_edge) down_edges.push_back(st);
    if (st.pen_up_edge) up_edges.push_back(st);
  }
  ASSERT_EQ(down_edges.size(), 2u);
  ASSERT_EQ(up_edges.size(), 2u);
  // Elevation runs linearly from -1 (lifted) to the pressure 0.4: contact begins where it
  // crosses 0, 1/1.4 of the way down (over the lead-in; over the second half of the gap before a
  // contact, the pen being above it by then); it ends 0.4/1.4 of the way up.
  const auto contains = [](const PlayerStep& step, double t) { return step.t_begin < t && t <= step.t; };
  EXPECT_TRUE(contains(down_edges[0], -s.lead_in + s.lead_in / 1.4)) << down_edges[0].t;
  EXPECT_TRUE(contains(down_edges[1], 0.85 + 0.05 / 1.4)) << down_edges[1].t;
  // The up edge is the first step that begins after the last contact.
  const double last_contact = 0.3 + 0.1 * 0.4 / 1.4;
  EXPECT_GT(up_edges[0].t_begin, last_contact);
  EXPECT_LE(up_edges[0].t_begin - s.dt, last_contact);
  EXPECT_GT(up_edges[1].t_begin, 1.2);
}

TEST(StrokePlayer, EventsFireOnceInTheirStep) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.4), pen(1.0, 300, 100, 0.4)});
  StrokeEvent dip;
  dip.kind = StrokeEventKind::Dip;
  dip.t = 0.0;
  StrokeEvent wipe;
  wipe.kind = StrokeEventKind::Wipe;
  wipe.t = 0.1;
  StrokeEvent clean = wipe;
  clean.kind = StrokeEventKind::Clean;
  StrokeEvent dry;
  dry.kind = StrokeEventKind::Dry;
  dry.t = 1.0;
  s.events = {dip, wipe, clean, dry};
  StrokePlayer player(s);
  PlayerStep st;
  std::map<const StrokeEvent*, int> fired;
  for (int pass = 0; pass < 2; ++pass) {  // rewind replays the same
    fired.clear();
    player.rewind();
    while (player.next(st)) {
      for (const StrokeEvent& e : st.events) {
        fired[&e]++;
        EXPECT_LE(e.t, st.t + 1e-12);
        EXPECT_GT(e.t, st.t_begin - 1e-12);
      }
    }
    ASSERT_EQ(fired.size(), 4u);
    for (const auto& [e, n] : fired) EXPECT_EQ(n, 1);
  }
}

TEST(StrokePlayer, SingleSampleStab) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.8)});
  StrokePlayer player(s);
  EXPECT_EQ(player.step_count(), 30);  // 0.5 s of lead-in and lead-out
  PlayerStep st;
  int down = 0;
  while (player.next(st)) down += st.pen_down;
  EXPECT_GE(down, 1);
}

TEST(StrokePlayer, RejectsInvalidStroke) {
  Stroke s = make_stroke({pen(0.0, 100, 100, 0.4), pen(0.0, 110, 100, 0.4)});
  EXPECT_THROW(StrokePlayer{s}, Error);
  s.samples.clear();
  EXPECT_THROW(StrokePlayer{s}, Error);
}

}  // namespace
}  // namespace wb

namespace wb {
namespace {

// The shipped examples load cleanly, stay short (quick replays) and touch the canvas.
TEST(StrokeExamples, LoadAndPlay) {
  const std::string dir = std::string(WB_SOURCE_DIR) + "/examples/";
  for (const char* name : {"press-and-drag.json", "s-curve-flat.json", "stab-and-roll.json", "tablet-scribble.txt"}) {
    const Stroke s = load_stroke(dir + name);
    EXPECT_TRUE(s.warnings.empty()) << name << ": " << s.warnings.front();
    EXPECT_GE(s.duration(), 1.0) << name;
    EXPECT_LE(s.duration(), 3.0) << name;
    StrokePlayer player(s);
    PlayerStep st;
    int edges = 0, down = 0;
    while (player.next(st)) {
      edges += st.pen_down_edge;
      down += st.pen_down;
      EXPECT_LE(st.max_move, s.max_move_per_substep + 1e-4f) << name << " step " << st.index;
    }
    EXPECT_GE(edges, 1) << name;
    EXPECT_GT(down, 30) << name;
  }
}

}  // namespace
}  // namespace wb
