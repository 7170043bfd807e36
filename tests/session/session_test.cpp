// wb::Session, the layer the CLI, the studio and Python paint through: a stroke is one undo unit,
// a saved painting opens again as it was, and what does not fit the session is refused.
#include "core/session/session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/exec/error.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

class SessionTest : public SimulatorTest {
 protected:
  /// The paint's total height over the canvas, cells (a map's sum).
  static double total(const FloatImage& h) {
    double s = 0.0;
    for (float v : h.data) s += v;
    return s;
  }
  static double max_difference(const FloatImage& a, const FloatImage& b) {
    EXPECT_EQ(a.data.size(), b.data.size());
    double d = 0.0;
    for (size_t i = 0; i < a.data.size() && i < b.data.size(); ++i) d = std::max(d, double(std::fabs(a.data[i] - b.data[i])));
    return d;
  }
  /// A pressed drag of 30 cells and the lift, through the session's stroke verbs.
  void paint_stroke(Session& s, float y) {
    const BrushSpec& b = s.config().brush;
    PaintLoad once = red();
    once.reload_on_pen_down = false;  // begin_stroke loads it
    s.begin_stroke(pose_at(b, 100.f, y, 0.f, false), once);
    const float dt = 1.f / 60.f;
    for (int i = 0; i < 10; ++i) {
      const BrushPose p = pose_at(b, 100.f + 3.f * float(i), y, 0.7f);
      s.step(&p, 1, dt);
    }
    for (int i = 0; i < 4; ++i) {
      const BrushPose p = pose_at(b, 130.f, y, 0.f, false);
      s.step(&p, 1, dt);
    }
    EXPECT_TRUE(s.end_stroke()) << "the stroke changed the canvas";
  }
};

TEST_F(SessionTest, AStrokeIsOneUndoUnitAndRedoPutsItBack) {
  Session s(small_config(), 4);
  EXPECT_FALSE(s.can_undo());
  paint_stroke(s, 100.f);
  const FloatImage first = s.height_map();
  paint_stroke(s, 150.f);
  const FloatImage both = s.height_map();
  std::printf("paint height summed: first stroke %.1f, both %.1f cells\n", total(first), total(both));
  ASSERT_GT(total(first), 10.0);
  ASSERT_GT(total(both), total(first) + 10.0);

  ASSERT_TRUE(s.undo());
  const double after_undo = max_difference(s.height_map(), first);
  ASSERT_TRUE(s.undo());
  const double blank = total(s.height_map());
  EXPECT_FALSE(s.undo()) << "two strokes, two undos";
  ASSERT_TRUE(s.redo());
  ASSERT_TRUE(s.redo());
  const double after_redo = max_difference(s.height_map(), both);
  std::printf("undo: %.2e cells from the first stroke's canvas; blank %.2e; redo: %.2e from both\n", after_undo, blank,
              after_redo);
  // Tiles are restored as they were stored (16-bit fields): within a quantum of the height.
  EXPECT_LT(after_undo, 1e-3);
  EXPECT_LT(blank, 1e-3);
  EXPECT_LT(after_redo, 1e-3);
  EXPECT_FALSE(s.redo());
}

TEST_F(SessionTest, LiftedStepsBetweenStrokesAreNoStrokeOfTheirOwn) {
  // Two strokes of a recording with the brush's lifted travel between them, each step followed by
  // end_stroke as a painting program does whenever it has caught up with the pen and the pen is
  // up. The travel (the first stroke's paint still landing, the window following the brush) is
  // no undo step of its own: two strokes, two undos.
  Session s(small_config(), 4);
  const auto pen = [](double t, float x, float y, bool down) {
    PenSample p;
    p.t = t, p.x = x, p.y = y, p.pressure = down ? 0.7f : 0.f, p.down = down;
    return p;
  };
  Stroke rec;
  rec.canvas = s.dims();
  rec.brush = s.config().brush;
  rec.paint = red();
  rec.samples = {pen(0.0, 100, 100, true), pen(0.3, 140, 100, true), pen(0.32, 140, 100, false),
                 pen(0.9, 100, 160, false), pen(0.95, 100, 160, true), pen(1.25, 140, 160, true),
                 pen(1.27, 140, 160, false)};
  rec.source = "test";
  StrokePlayer player(rec);
  s.begin_stroke(player.pose_at(player.t_begin()), rec.paint);
  PlayerStep st;
  int records = 0, lifted_ends = 0;
  FloatImage first;
  while (player.next(st)) {
    s.step(player, st, st.events, st.pen_down_edge);
    if (st.pen_down) continue;
    const bool kept = s.end_stroke();
    records += kept;
    if (kept && records == 1) first = s.height_map();
    lifted_ends += st.t > 0.5 && st.t < 0.9;
  }
  EXPECT_GT(lifted_ends, 10) << "end_stroke was asked during the travel";
  EXPECT_EQ(records, 2);
  ASSERT_TRUE(s.undo());
  const double after_undo = max_difference(s.height_map(), first);
  ASSERT_TRUE(s.undo());
  EXPECT_FALSE(s.undo()) << "two strokes, two undos";
  EXPECT_LT(total(s.height_map()), 1e-3);
  EXPECT_LT(after_undo, 1e-3) << "one undo goes back to the first stroke's painting";
}

TEST_F(SessionTest, ASavedPaintingOpensWithItsBrushPaperAndPaint) {
  SimConfig c = small_config();
  c.params.render.paper_rgb = Vec3(0.8f, 0.7f, 0.6f);
  Session s(c);
  PaintLoad blue = red();
  blue.ryb[0] = 0.05f, blue.ryb[2] = 0.9f;
  s.put_paint(60.f, 60.f, 10.f, 3.f, blue);
  const FloatImage h = s.height_map();
  ASSERT_GT(total(h), 100.0);
  const std::string path = (std::filesystem::temp_directory_path() / "wb_session_test.ora").string();
  s.save(path, {{"generator", "SessionTest"}});

  SimConfig base;
  base.device = device_;
  const std::unique_ptr<Session> o = Session::open(path, base);
  std::filesystem::remove(path);
  EXPECT_TRUE(o->dims() == c.canvas);
  EXPECT_EQ(o->config().brush.bristles, c.brush.bristles) << "the brush the metadata names";
  EXPECT_FLOAT_EQ(o->config().brush.length, c.brush.length);
  EXPECT_NEAR(o->renderer().params().paper_rgb.y, 0.7f, 1e-6f);
  EXPECT_LT(max_difference(o->height_map(), h), 1e-3);
  const std::optional<Vec3> at = o->pick(60, 60);
  ASSERT_TRUE(at.has_value());
  EXPECT_GT(at->z, 0.8f) << "the dab's blue";
  EXPECT_FALSE(o->pick(200, 200).has_value()) << "bare canvas";
}

TEST_F(SessionTest, ThinPaintOnAWovenGroundLooksTheSameWhenItHasDried) {
  // A glaze (0.3 cells) and a thicker dab (0.8 cells) on a primed linen ground, then the canvas
  // dries: the paint's colour and relief are what they were wet (the dried glaze once rendered as
  // the bare primer, its cells being paint above dried paint that was no wetter than it).
  Session s(small_config());
  s.lay_ground(CanvasGround::of(Weave::Linen));
  PaintLoad blue = red();
  blue.ryb[0] = 0.f, blue.ryb[1] = 0.1f, blue.ryb[2] = 0.9f;
  s.put_paint(50.f, 60.f, 14.f, 0.3f, blue);
  s.put_paint(100.f, 60.f, 14.f, 0.8f, blue);
  const FloatImage a0 = s.albedo(), h0 = s.height_map();
  StrokeEvent dry;
  dry.kind = StrokeEventKind::Dry;
  s.apply(dry);
  const FloatImage a1 = s.albedo(), h1 = s.height_map();
  for (const int cx : {50, 100}) {
    double wet = 0.0, dried = 0.0, dh = 0.0;
    for (int y = 54; y < 66; ++y)
      for (int x = cx - 6; x < cx + 6; ++x) {
        wet += a0.at(x, y, 2) - a0.at(x, y, 0);  // blue over red: the glaze's colour against the primer's
        dried += a1.at(x, y, 2) - a1.at(x, y, 0);
        dh = std::max(dh, double(std::fabs(h1.at(x, y) - h0.at(x, y))));
      }
    wet /= 144.0, dried /= 144.0;
    std::printf("dab at x %d: blue - red %.3f wet, %.3f dried; largest height change %.3f cells\n", cx, wet, dried, dh);
    EXPECT_GT(wet, 0.15) << "the paint shows over the primer";
    EXPECT_NEAR(dried, wet, 0.02) << "and still does when it has dried";
    EXPECT_LT(dh, 0.05) << "its relief is the same dried";
  }
}

TEST_F(SessionTest, APaintingsUnreadableRecordsCostThoseRecordsNotThePainting) {
  // A paper out of range and a brush and ground of the wrong kind: the painting opens with the
  // defaults for them (a warning each), its paint as saved.
  SimConfig c = small_config();
  Session s(c);
  s.put_paint(40.f, 40.f, 6.f, 2.f, red());
  PaintingSnapshot snap = s.snapshot();
  snap.metadata["paper_rgb"] = {5.0, 0.0, 0.0};
  snap.metadata["brush"] = {{"bristles", -3}};
  snap.metadata["ground"] = {{"weave", "no such weave"}};
  const std::string path = (std::filesystem::temp_directory_path() / "wb_session_records.ora").string();
  write_painting(path, snap);
  SimConfig base;
  base.device = device_;
  const std::unique_ptr<Session> o = Session::open(path, base);
  std::filesystem::remove(path);
  const Vec3 paper = o->renderer().params().paper_rgb, fallback = SimConfig{}.params.render.paper_rgb;
  EXPECT_EQ(paper.x, fallback.x);
  EXPECT_EQ(o->config().brush.bristles, SimConfig{}.brush.bristles);
  EXPECT_FALSE(o->ground().has_value());
  EXPECT_LT(max_difference(o->height_map(), s.height_map()), 1e-3);
}

TEST_F(SessionTest, AStrokeOfAnotherCanvasOrNonsenseIsRefusedWithItsReason) {
  Session s(small_config());
  Stroke other;
  other.canvas = CanvasDims{128, 128, 16};
  other.source = "other.json";
  PenSample p;
  p.x = 10.f, p.y = 10.f;
  other.samples = {p};
  try {
    s.begin_replay(other);
    FAIL() << "a stroke of another canvas replayed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not this session's"), std::string::npos) << e.what();
  }
  EXPECT_THROW(s.put_paint(10.f, 10.f, std::nanf(""), 1.f, red()), Error);
  EXPECT_THROW(s.advance(), Error) << "no replay begun";
}

TEST_F(SessionTest, APaletteDabLeavesTheBrushRoomUnderTheWindowsLid) {
  // The window's top is a lid nothing rises through. A palette's dab, scrubbed by the brush, has
  // its ridges ploughed up over it: it is put out no higher than half the window's depth, and the
  // scrubbed paint stays under the lid. A 200-cell palette and an 8-cell window: a dab a third as
  // high as wide would be 12 cells high, above the lid from the start.
  SimConfig c = small_config(CanvasDims{200, 120, 32});
  c.window = Int3{48, 48, 8};
  const DabSize dab = palette_dab_size(c);
  EXPECT_FLOAT_EQ(dab.radius, 12.f);
  EXPECT_LE(dab.height, 0.5f * float(c.window.z));
  Session s(c);
  s.put_paint(100.f, 60.f, dab.radius, dab.height, red());
  const auto highest = [&] {
    const FloatImage h = s.height_map();
    return *std::max_element(h.data.begin(), h.data.end());
  };
  const float before = highest();
  const BrushSpec& b = s.config().brush;
  PaintLoad none = red();
  none.load = 0.f;
  none.reload_on_pen_down = false;
  s.begin_stroke(pose_at(b, 70.f, 60.f, 0.f, false), none);
  for (int i = 0; i <= 40; ++i) {
    const BrushPose p = pose_at(b, 70.f + 1.5f * float(i), 60.f, 0.6f);
    s.step(&p, 1, 1.f / 60.f);
  }
  s.end_stroke();
  const float after = highest();
  std::printf("palette dab: %.1f cells high put out, %.2f high scrubbed; the window's lid at %d\n", before, after,
              c.window.z);
  EXPECT_NEAR(before, dab.height, 0.5f);
  EXPECT_LT(after, float(c.window.z) - 1.f) << "the scrubbed paint stays under the lid";
}

}  // namespace
}  // namespace wb::test
