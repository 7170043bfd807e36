// Stroke input: JSON stroke format and format detection; good and bad fixtures
// (tests/data/strokes/{good,bad}), warnings, save/load round trip.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/exec/error.h"
#include "core/io/brush_json.h"
#include "core/io/stroke.h"

namespace wb {
namespace {

std::string fixture(const std::string& rel) { return std::string(WB_TEST_DATA_DIR) + "/strokes/" + rel; }

bool has_warning(const Stroke& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

TEST(StrokeJson, MinimalUsesDefaults) {
  const Stroke s = load_stroke(fixture("good/minimal.json"));
  EXPECT_EQ(s.source, fixture("good/minimal.json"));
  EXPECT_EQ(s.canvas.width, 512);
  EXPECT_EQ(s.canvas.height, 256);
  EXPECT_EQ(s.canvas.depth, 64);
  EXPECT_FALSE(s.paper_rgb.has_value());
  EXPECT_EQ(s.brush, default_brush(BrushShape::Round));
  EXPECT_EQ(s.paint, PaintLoad{});
  EXPECT_DOUBLE_EQ(s.dt, 1.0 / 60.0);
  ASSERT_EQ(s.samples.size(), 2u);
  EXPECT_DOUBLE_EQ(s.samples[1].t, 0.5);
  EXPECT_FLOAT_EQ(s.samples[1].x, 200.f);
  EXPECT_FLOAT_EQ(s.samples[1].pressure, 0.6f);
  EXPECT_TRUE(s.samples[0].down);
  EXPECT_FLOAT_EQ(s.samples[0].tilt_x, 0.f);
  EXPECT_TRUE(s.events.empty());
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_DOUBLE_EQ(s.duration(), 0.5);
}

TEST(StrokeJson, FullReadsEveryKey) {
  const Stroke s = load_stroke(fixture("good/full.json"));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_EQ(s.canvas, (CanvasDims{1024, 768, 48}));
  ASSERT_TRUE(s.paper_rgb.has_value());
  EXPECT_FLOAT_EQ((*s.paper_rgb)[2], 0.88f);
  BrushSpec b = default_brush(BrushShape::Flat);
  b.bristles = 320;
  b.length = 90.f;
  b.width = 60.f;
  b.stiffness = 0.8f;
  b.max_press = 0.4f;
  b.seed = 7;
  EXPECT_EQ(s.brush, b);  // starts from the flat defaults, overrides what is given
  EXPECT_FLOAT_EQ(s.paint.ryb[0], 0.9f);
  EXPECT_FLOAT_EQ(s.paint.oil, 0.4f);
  EXPECT_FLOAT_EQ(s.paint.load, 0.7f);
  EXPECT_FALSE(s.paint.reload_on_pen_down);
  EXPECT_DOUBLE_EQ(s.dt, 0.02);
  EXPECT_FLOAT_EQ(s.max_move_per_substep, 1.5f);
  EXPECT_EQ(s.max_substeps, 32);
  EXPECT_DOUBLE_EQ(s.lead_in, 0.1);
  EXPECT_DOUBLE_EQ(s.lead_out, 0.2);
  ASSERT_EQ(s.samples.size(), 5u);
  EXPECT_FLOAT_EQ(s.samples[1].tilt_x, 20.f);
  EXPECT_FLOAT_EQ(s.samples[1].tilt_y, -10.f);
  EXPECT_FLOAT_EQ(s.samples[2].twist, 30.f);
  EXPECT_FALSE(s.samples[3].down);
  EXPECT_FLOAT_EQ(s.samples[4].tilt_y, 0.f);
  ASSERT_EQ(s.events.size(), 4u);
  EXPECT_EQ(s.events[0].kind, StrokeEventKind::Wipe);
  EXPECT_FLOAT_EQ(s.events[0].fraction, 0.3f);
  EXPECT_EQ(s.events[1].kind, StrokeEventKind::Dip);
  EXPECT_FLOAT_EQ(s.events[1].ryb[1], 0.8f);
  EXPECT_FLOAT_EQ(s.events[1].oil, 0.5f);
  EXPECT_FLOAT_EQ(s.events[1].load, 0.9f);
  EXPECT_EQ(s.events[2].kind, StrokeEventKind::Clean);
  EXPECT_EQ(s.events[3].kind, StrokeEventKind::Dry);
  EXPECT_DOUBLE_EQ(s.events[3].t, 0.4);
}

TEST(StrokeJson, UnknownKeysWarnWithTheirPlace) {
  const Stroke s = load_stroke(fixture("good/unknown-keys.json"));
  EXPECT_TRUE(has_warning(s, "top level: unknown key 'author'"));
  EXPECT_TRUE(has_warning(s, "canvas: unknown key 'colour'"));
  EXPECT_TRUE(has_warning(s, "brush: unknown key 'hairiness'"));
  EXPECT_TRUE(has_warning(s, "paint: unknown key 'gloss'"));
  EXPECT_TRUE(has_warning(s, "samples[0]: unknown key 'azimuth' ignored (in 2 samples)"));
  EXPECT_TRUE(has_warning(s, "events[0]: unknown key 'solvent'"));
  EXPECT_TRUE(has_warning(s, "samples[2]: tilt beyond 80 degrees is clamped"));
  EXPECT_EQ(s.warnings.size(), 7u);
  for (const std::string& w : s.warnings) EXPECT_NE(w.find("unknown-keys.json"), std::string::npos) << w;
  // Paint keys not given keep their defaults.
  EXPECT_FLOAT_EQ(s.paint.oil, PaintLoad{}.oil);
  EXPECT_FLOAT_EQ(s.paint.ryb[2], 1.f);
}

struct BadCase {
  const char* file;
  std::vector<const char*> parts;  // every one must appear in the message
};

class StrokeBad : public ::testing::TestWithParam<BadCase> {};

TEST_P(StrokeBad, RejectedWithPreciseMessage) {
  const BadCase& c = GetParam();
  const std::string path = fixture(std::string("bad/") + c.file);
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  try {
    load_stroke(path);
    FAIL() << c.file << " was accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    for (const char* part : c.parts) EXPECT_NE(msg.find(part), std::string::npos) << "missing '" << part << "' in: " << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, StrokeBad,
    ::testing::Values(
        BadCase{"truncated.json", {":7:", "JSON syntax error", "unexpected end of input"}},
        BadCase{"missing-samples.json", {"top level", "missing required key 'samples'"}},
        BadCase{"missing-version.json", {"missing required key 'version'"}},
        BadCase{"newer-version.json", {"version: version 2 was written by a newer wetbrush", "reads version 1"}},
        BadCase{"nan-string.json", {"samples[2].pressure", "expected a number, found a string (\"NaN\")"}},
        BadCase{"pressure-1.5.json", {"samples[1].pressure", "1.5 is outside [0, 1]"}},
        BadCase{"out-of-order-t.json", {"samples[3]", "t = 0.25 is not after samples[2].t = 0.3"}},
        BadCase{"off-canvas.json", {"samples[2]", "(500, 300) is off the 512 x 256 canvas"}},
        BadCase{"wrong-types.json", {"samples[1].x", "expected a number, found an array"}},
        BadCase{"empty.json", {"empty file"}},
        BadCase{"binary-garbage.bin", {":1:", "binary data", "not a stroke file"}},
        BadCase{"mypaint-3-columns.txt", {":4:", "expected 4 columns", "found 3"}},
        BadCase{"mypaint-non-numeric.txt", {":3:", "column 3 (y): 'abc' is not a number"}},
        BadCase{"mypaint-nan.txt", {":2:", "column 4 (pressure): 'nan' is not a finite"}},
        BadCase{"mypaint-time-order.txt", {":3:", "t = 0.005 is earlier than the previous event's t = 0.01 (line 2)"}},
        BadCase{"wrong-format.json", {"format", "expected \"wetbrush-stroke\""}},
        BadCase{"brush-out-of-range.json", {"brush.bristles", "1000 is outside [40, 600]"}},
        BadCase{"unknown-shape.json", {"brush.shape: unknown brush shape 'sponge'"}},
        BadCase{"number-overflow.json", {":5:31:", "number overflow"}},
        BadCase{"absurd-magnitude.json", {"samples[1].twist", "not a plausible value"}},
        BadCase{"unknown-event.json", {"events[1].type", "unknown event type \"splash\""}},
        BadCase{"not-an-object.json", {"top level: expected an object, found an array"}},
        BadCase{"ground-unknown-weave.json", {"canvas.ground.weave: unknown weave 'burlap'"}},
        BadCase{"ground-too-thick.json", {"canvas.ground", "thicker than half the canvas's paint depth", "refused"}},
        BadCase{"ground-too-large.json", {"canvas.ground", "224.0 GiB of paint", "refused"}},
        BadCase{"longer-than-a-week.txt", {"the samples span 700000.01 s, more than a week (604800 s)"}}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string n = info.param.file;
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(StrokeBad, EveryFixtureIsCovered) {
  // A new bad fixture must get an expectation above.
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(fixture("bad"))) files += e.is_regular_file();
  EXPECT_EQ(files, 26u);
}

TEST(StrokeJson, MissingFileNamesIt) {
  try {
    load_stroke("/nonexistent/dir/stroke.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/stroke.json"), std::string::npos);
  }
}

TEST(StrokeJson, SyntaxErrorLineAndColumn) {
  // The error is the missing ':' on line 3, column 12.
  const std::string text = "{\n  \"format\": \"wetbrush-stroke\",\n  \"version\" 1\n}";
  try {
    parse_stroke_json(text, "mem.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mem.json:3:13:"), std::string::npos) << e.what();
  }
}

TEST(StrokeJson, EventAfterLastSampleRejected) {
  const std::string text = R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 64, "height": 64},
    "samples": [{"t": 0, "x": 1, "y": 1, "pressure": 0}, {"t": 1, "x": 2, "y": 1, "pressure": 0}],
    "events": [{"type": "dry", "t": 1.5}]})";
  EXPECT_THROW(parse_stroke_json(text, "m.json"), Error);
}

TEST(StrokeJson, CanvasGroundIsReadCheckedAndKept) {
  auto with_ground = [](const std::string& g) {
    return R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 512, "height": 512, "ground": )" + g +
           R"(}, "samples": [{"t": 0, "x": 10, "y": 10, "pressure": 0.5}]})";
  };
  const Stroke st = parse_stroke_json(with_ground(R"({"weave": "cotton_duck", "relief_mm": 0.25})"), "g.json");
  ASSERT_TRUE(st.ground.has_value());
  EXPECT_EQ(st.ground->weave, Weave::CottonDuck);
  EXPECT_FLOAT_EQ(st.ground->thread_mm, 0.8f) << "the weave's default";
  EXPECT_FLOAT_EQ(st.ground->relief_mm, 0.25f);
  EXPECT_EQ(parse_stroke_json(stroke_to_json_string(st), "again.json").ground, st.ground);
  EXPECT_FALSE(parse_stroke_json(with_ground("{}"), "g.json").ground->weave != Weave::Smooth);
  for (const char* bad : {R"({"weave": "burlap"})", R"({"weave": 3})", R"({"thread_mm": 0.1})", R"({"relief_mm": -1})",
                          R"({"relief_mm": 1e400})", R"({"relief_mm": "0.3"})", R"({"thread": 1})", "[1, 2]"}) {
    try {
      parse_stroke_json(with_ground(bad), "g.json");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("g.json"), std::string::npos) << e.what();
    }
  }
}

TEST(StrokeJson, SimulationWindowIsReadCheckedAndKept) {
  auto with_window = [](const std::string& w) {
    return R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 512, "height": 512}, "simulation": {"window": )" + w +
           R"(}, "samples": [{"t": 0, "x": 10, "y": 10, "pressure": 0.5}]})";
  };
  const Stroke st = parse_stroke_json(with_window("[192, 160, 32]"), "w.json");
  ASSERT_TRUE(st.window.has_value());
  EXPECT_EQ((*st.window)[0], 192);
  EXPECT_EQ((*st.window)[1], 160);
  EXPECT_EQ((*st.window)[2], 32);
  EXPECT_EQ(parse_stroke_json(stroke_to_json_string(st), "again.json").window, st.window);
  EXPECT_THROW(parse_stroke_json(with_window("[192.5, 160, 32]"), "w.json"), Error) << "whole cells only";
  EXPECT_THROW(parse_stroke_json(with_window("[8, 160, 32]"), "w.json"), Error) << "too narrow";
  EXPECT_THROW(parse_stroke_json(with_window("[192, 160]"), "w.json"), Error);
  EXPECT_THROW(parse_stroke_json(with_window("[4096, 160, 32]"), "w.json"), Error);
}

TEST(StrokeJson, CanvasTiltIsReadCheckedAndKept) {
  auto with_tilt = [](const std::string& t) {
    return R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 512, "height": 512, "tilt": )" + t +
           R"(}, "samples": [{"t": 0, "x": 10, "y": 10, "pressure": 0.5}]})";
  };
  const Stroke st = parse_stroke_json(with_tilt("75"), "t.json");
  ASSERT_TRUE(st.tilt.has_value());
  EXPECT_EQ(*st.tilt, 75.f);
  EXPECT_EQ(parse_stroke_json(stroke_to_json_string(st), "again.json").tilt, st.tilt);
  EXPECT_FALSE(parse_stroke_json(R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 64, "height": 64},
      "samples": [{"t": 0, "x": 10, "y": 10, "pressure": 0.5}]})", "flat.json").tilt.has_value());
  for (const char* bad : {"-5", "91", "\"upright\"", "null"}) {
    try {
      parse_stroke_json(with_tilt(bad), "t.json");
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("tilt"), std::string::npos) << e.what();
    }
  }
}

TEST(StrokeJson, SaveLoadRoundTrip) {
  Stroke a = load_stroke(fixture("good/full.json"));
  a.samples[2].x = 123.456789f;  // not a short decimal
  a.samples[2].t = 0.2000000000001;
  a.brush.length_variation = 0.1f;
  const std::string path = ::testing::TempDir() + "/wb_roundtrip_stroke.json";
  save_stroke_json(a, path);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const Stroke b = load_stroke(path);
  EXPECT_TRUE(b.warnings.empty());
  EXPECT_EQ(b.canvas, a.canvas);
  EXPECT_EQ(b.paper_rgb, a.paper_rgb);
  EXPECT_EQ(b.brush, a.brush);
  EXPECT_EQ(b.paint, a.paint);
  EXPECT_EQ(b.events, a.events);
  EXPECT_EQ(b.dt, a.dt);
  EXPECT_EQ(b.max_move_per_substep, a.max_move_per_substep);
  EXPECT_EQ(b.max_substeps, a.max_substeps);
  EXPECT_EQ(b.lead_in, a.lead_in);
  EXPECT_EQ(b.lead_out, a.lead_out);
  ASSERT_EQ(b.samples.size(), a.samples.size());
  for (size_t i = 0; i < a.samples.size(); ++i) {
    const PenSample &p = a.samples[i], &q = b.samples[i];
    EXPECT_EQ(p.t, q.t);
    EXPECT_EQ(p.x, q.x);
    EXPECT_EQ(p.y, q.y);
    EXPECT_EQ(p.pressure, q.pressure);
    EXPECT_EQ(p.tilt_x, q.tilt_x);
    EXPECT_EQ(p.tilt_y, q.tilt_y);
    EXPECT_EQ(p.twist, q.twist);
    EXPECT_EQ(p.down, q.down);
  }
  // Short decimals stay short in the file.
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"oil\":0.4"), std::string::npos);
  std::remove(path.c_str());
}

TEST(StrokeJson, SaveRefusesInvalidStroke) {
  Stroke s = load_stroke(fixture("good/minimal.json"));
  s.samples[1].pressure = 2.f;
  const std::string path = ::testing::TempDir() + "/wb_invalid_stroke.json";
  EXPECT_THROW(save_stroke_json(s, path), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(BrushJson, RoundTripAndOverrides) {
  BrushSpec b = default_brush(BrushShape::Fan);
  b.bristles = 555;
  b.beta_B = 0.02f;
  EXPECT_EQ(brush_from_json(brush_to_json(b), "b", ""), b);
  const auto j = nlohmann::json::parse(R"({"shape": "rigger", "length": 150})");
  BrushSpec want = default_brush(BrushShape::Rigger);
  want.length = 150.f;
  EXPECT_EQ(brush_from_json(j, "b", ""), want);
  EXPECT_THROW(brush_from_json(nlohmann::json::parse(R"({"bristles": 100.5})"), "b", ""), Error);
  EXPECT_THROW(brush_from_json(nlohmann::json::parse(R"({"length": "long"})"), "b", ""), Error);
  EXPECT_THROW(brush_from_json(nlohmann::json::parse(R"({"length": 0})"), "b", ""), Error);
  EXPECT_THROW(brush_from_json(nlohmann::json::parse(R"([1])"), "b", ""), Error);
  // A seed's range is wider than the readers' plausibility bound (1e7) and is honoured.
  EXPECT_EQ(brush_from_json(nlohmann::json::parse(R"({"seed": 3000000000})"), "b", "").seed, 3000000000u);
  // Every shape's defaults lie in the documented ranges.
  for (BrushShape s : {BrushShape::Round, BrushShape::Flat, BrushShape::Fan, BrushShape::Filbert, BrushShape::Angular,
                       BrushShape::Mop, BrushShape::Rigger})
    EXPECT_NO_THROW(validate_brush(default_brush(s), to_string(s)));
}

}  // namespace
}  // namespace wb
