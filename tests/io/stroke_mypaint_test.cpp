// Stroke input: MyPaint event dumps (t x y pressure [xtilt ytilt]) and their clamps.
#include <gtest/gtest.h>

#include <string>

#include "core/exec/error.h"
#include "core/io/stroke.h"

namespace wb {
namespace {

std::string fixture(const std::string& rel) { return std::string(WB_TEST_DATA_DIR) + "/strokes/" + rel; }

bool has_warning(const Stroke& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

TEST(StrokeMyPaint, TabletFixture) {
  const std::string path = fixture("good/tablet.txt");
  const Stroke s = load_stroke(path);
  EXPECT_EQ(s.brush, default_brush(BrushShape::Round));
  EXPECT_EQ(s.paint, PaintLoad{});
  EXPECT_TRUE(s.paint.reload_on_pen_down);
  EXPECT_EQ(s.canvas, CanvasDims{});
  // 8 event lines, two share t = 1000.015: the later replaces the earlier.
  ASSERT_EQ(s.samples.size(), 7u);
  EXPECT_DOUBLE_EQ(s.samples[0].t, 0.0);  // rebased to the first event
  EXPECT_NEAR(s.samples[6].t, 0.030, 1e-9);
  EXPECT_FALSE(s.samples[0].down);  // pressure 0 = pen up
  EXPECT_FALSE(s.samples[1].down);
  EXPECT_TRUE(s.samples[2].down);
  EXPECT_FLOAT_EQ(s.samples[2].pressure, 0.25f);
  EXPECT_NEAR(s.samples[2].tilt_x, 6.f, 1e-5f);    // 0.1 * 60 degrees
  EXPECT_NEAR(s.samples[2].tilt_y, -12.f, 1e-5f);  // -0.2 * 60 degrees
  EXPECT_FLOAT_EQ(s.samples[3].x, 104.5f);          // the replacing event
  EXPECT_FLOAT_EQ(s.samples[3].tilt_x, 0.f);
  EXPECT_FLOAT_EQ(s.samples[4].pressure, 1.f);      // 1.03 clamped
  EXPECT_FLOAT_EQ(s.samples[5].x, 0.f);             // -3 clamped to the canvas edge
  EXPECT_FALSE(s.samples[6].down);

  EXPECT_TRUE(has_warning(s, path + ":7: xtilt/ytilt outside [-1, 1] clamped (1 events"));
  EXPECT_TRUE(has_warning(s, path + ":9: pressure outside [0, 1] clamped (1 events"));
  EXPECT_TRUE(has_warning(s, path + ":10: position off the 4096 x 4096 canvas clamped"));
  EXPECT_TRUE(has_warning(s, path + ":8: event with the same t"));
  EXPECT_EQ(s.warnings.size(), 4u);
}

TEST(StrokeMyPaint, FiveColumnsRejected) {
  try {
    parse_mypaint_events("0 1 1 0.5\n0.01 2 1 0.5 0.3\n", "five.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("five.txt:2: expected 4 columns"), std::string::npos) << e.what();
  }
}

TEST(StrokeMyPaint, OnlyCommentsIsAnError) {
  try {
    parse_mypaint_events("# nothing here\n\n   \n", "c.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("c.txt: no events"), std::string::npos) << e.what();
  }
}

TEST(StrokeMyPaint, InfinityAndHugeValuesRejected) {
  EXPECT_THROW(parse_mypaint_events("0 1 1 0.5\n0.01 inf 1 0.5\n", "i.txt"), Error);
  EXPECT_THROW(parse_mypaint_events("0 1 1 0.5\n0.01 1e30 1 0.5\n", "h.txt"), Error);
  EXPECT_THROW(parse_mypaint_events("0 1 1 0.5x\n", "x.txt"), Error);
}

TEST(StrokeMyPaint, CrLfAndPlusSign) {
  const Stroke s = parse_mypaint_events("0 1 1 0.5\r\n0.01 +2 1 0.5\r\n", "crlf.txt");
  ASSERT_EQ(s.samples.size(), 2u);
  EXPECT_FLOAT_EQ(s.samples[1].x, 2.f);
  EXPECT_TRUE(s.warnings.empty());
}

}  // namespace
}  // namespace wb
