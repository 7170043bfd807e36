// Stroke input, JSON format "wetbrush-stroke" version 1 (docs/FORMATS.md): reading with
// precise messages (file, line:column for syntax, key path and sample index for values),
// atomic writing, format detection, and the invariants every loaded stroke satisfies.
#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "core/exec/error.h"
#include "core/io/atomic_file.h"
#include "core/io/brush_json.h"
#include "core/io/json_reader.h"
#include "core/io/pen_pose.h"
#include "core/io/stroke.h"
#include "core/grid/grid_params.h"
#include "core/io/limits.h"

namespace wb {

using nlohmann::json;

namespace {

constexpr const char* kFormatName = "wetbrush-stroke";
/// 1-based line and column of the character that nlohmann's parse_error::byte (1-based) points at.
std::pair<size_t, size_t> line_column(std::string_view text, size_t byte) {
  size_t line = 1, col = 1;
  size_t end = std::min(text.size(), byte > 0 ? byte - 1 : 0);
  // Input ended early: point just past its last visible character, not at the trailing newline.
  if (end >= text.size())
    while (end > 0 && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
  for (size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {line, col};
}

/// nlohmann's message without its "[json.exception...] parse error at line L, column C: " prefix.
std::string parse_error_detail(const std::string& what) {
  size_t p = what.find("column ");
  if (p != std::string::npos) {
    p = what.find(": ", p);
    if (p != std::string::npos) return what.substr(p + 2);
  }
  p = what.find("] ");
  return p == std::string::npos ? what : what.substr(p + 2);
}

StrokeEventKind event_kind_from(const std::string& s, const ObjectReader& r) {
  if (s == "dip") return StrokeEventKind::Dip;
  if (s == "wipe") return StrokeEventKind::Wipe;
  if (s == "clean") return StrokeEventKind::Clean;
  if (s == "dry") return StrokeEventKind::Dry;
  r.fail("unknown event type \"" + s + "\" (expected dip, wipe, clean or dry)", "type");
}

void read_samples(const json& arr, Stroke& st) {
  const std::string& src = st.source;
  if (!arr.is_array()) WB_THROW(src + ": samples: expected an array, found " + json_type_name(arr));
  if (arr.empty()) WB_THROW(src + ": samples: empty (a stroke needs at least one sample)");
  st.samples.reserve(arr.size());
  std::map<std::string, std::pair<size_t, size_t>> unknown;  // key -> (first sample, count)
  size_t tilt_clamped = 0, first_tilt_clamped = 0;
  for (size_t i = 0; i < arr.size(); ++i) {
    ObjectReader r(arr[i], src, "samples[" + std::to_string(i) + "]");
    PenSample s;
    s.t = r.number("t", 0.0, kAbsurdValue);
    s.x = float(r.number("x", -kAbsurdValue, kAbsurdValue));
    s.y = float(r.number("y", -kAbsurdValue, kAbsurdValue));
    s.pressure = float(r.number("pressure", 0.0, 1.0));
    s.tilt_x = float(r.number_or("tilt_x", 0.0, -90.0, 90.0));
    s.tilt_y = float(r.number_or("tilt_y", 0.0, -90.0, 90.0));
    s.twist = float(r.number_or("twist", 0.0, -kAbsurdValue, kAbsurdValue));
    s.down = r.boolean_or("down", true);
    if (std::fabs(s.tilt_x) > kMaxTiltDeg || std::fabs(s.tilt_y) > kMaxTiltDeg) {
      if (tilt_clamped++ == 0) first_tilt_clamped = i;
    }
    for (const std::string& k : r.unknown_keys()) {
      auto [it, fresh] = unknown.try_emplace(k, i, 0);
      it->second.second++;
    }
    st.samples.push_back(s);
  }
  for (const auto& [k, v] : unknown)
    st.warnings.push_back(src + ": samples[" + std::to_string(v.first) + "]: unknown key '" + k + "' ignored (in " +
                          std::to_string(v.second) + " samples)");
  if (tilt_clamped)
    st.warnings.push_back(src + ": samples[" + std::to_string(first_tilt_clamped) + "]: tilt beyond " +
                          number_text(kMaxTiltDeg) + " degrees is clamped to it (" + std::to_string(tilt_clamped) +
                          " samples)");
}

void read_events(const json& arr, Stroke& st) {
  const std::string& src = st.source;
  if (!arr.is_array()) WB_THROW(src + ": events: expected an array, found " + json_type_name(arr));
  for (size_t i = 0; i < arr.size(); ++i) {
    ObjectReader r(arr[i], src, "events[" + std::to_string(i) + "]");
    StrokeEvent e;
    e.kind = event_kind_from(r.string("type"), r);
    e.t = r.number("t", 0.0, kAbsurdValue);
    if (e.kind == StrokeEventKind::Dip) {
      const auto ryb = r.triple("ryb", 0.0, 1.0);
      for (int c = 0; c < 3; ++c) e.ryb[c] = ryb[c];
      e.oil = float(r.number_or("oil", st.paint.oil, 0.0, 1.0));
      e.load = float(r.number_or("load", 1.0, 0.0, 1.0));
    } else if (e.kind == StrokeEventKind::Wipe) {
      e.fraction = float(r.number_or("fraction", 0.5, 0.0, 1.0));
    }
    r.warn_unknown(st.warnings);
    st.events.push_back(e);
  }
}

}  // namespace

const char* to_string(StrokeEventKind k) {
  switch (k) {
    case StrokeEventKind::Dip: return "dip";
    case StrokeEventKind::Wipe: return "wipe";
    case StrokeEventKind::Clean: return "clean";
    case StrokeEventKind::Dry: return "dry";
  }
  return "?";
}

void validate_stroke(const Stroke& st) {
  const std::string& src = st.source.empty() ? std::string("<stroke>") : st.source;
  const auto sample = [&](size_t i) { return src + ": samples[" + std::to_string(i) + "]: "; };
  if (st.samples.empty()) WB_THROW(src + ": no samples (a stroke needs at least one)");
  WB_REQUIRE(st.dt >= 1e-4 && st.dt <= 0.1,
             src + ": simulation.dt = " + number_text(st.dt) + " is outside [0.0001, 0.1]");
  WB_REQUIRE(st.max_move_per_substep >= 0.1f && st.max_move_per_substep <= 100.f,
             src + ": simulation.max_move_per_substep is outside [0.1, 100]");
  WB_REQUIRE(st.max_substeps >= 1 && st.max_substeps <= 1024, src + ": simulation.max_substeps is outside [1, 1024]");
  WB_REQUIRE(!st.tilt || (std::isfinite(*st.tilt) && *st.tilt >= 0.f && *st.tilt <= 90.f),
             src + ": canvas.tilt is outside [0, 90] degrees");
  WB_REQUIRE(st.lead_in >= 0 && st.lead_in <= 5 && st.lead_out >= 0 && st.lead_out <= 5,
             src + ": simulation.lead_in / lead_out must lie in [0, 5] seconds");
  for (size_t i = 0; i < st.samples.size(); ++i) {
    const PenSample& s = st.samples[i];
    if (!std::isfinite(s.t) || !std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.pressure) ||
        !std::isfinite(s.tilt_x) || !std::isfinite(s.tilt_y) || !std::isfinite(s.twist))
      WB_THROW(sample(i) + "a value is not finite");
    if (s.pressure < 0.f || s.pressure > 1.f)
      WB_THROW(sample(i) + "pressure " + number_text(s.pressure) + " is outside [0, 1]");
    if (s.x < 0.f || s.y < 0.f || s.x > float(st.canvas.width) || s.y > float(st.canvas.height))
      WB_THROW(sample(i) + "(" + number_text(s.x) + ", " + number_text(s.y) + ") is off the " +
               std::to_string(st.canvas.width) + " x " + std::to_string(st.canvas.height) + " canvas");
    if (i > 0 && !(s.t > st.samples[i - 1].t))
      WB_THROW(sample(i) + "t = " + number_text(s.t) + " is not after samples[" + std::to_string(i - 1) +
               "].t = " + number_text(st.samples[i - 1].t) + " (samples must be strictly increasing in time)");
  }
  const double span = st.samples.back().t - st.samples.front().t;
  WB_REQUIRE(span <= kMaxStrokeSeconds, src + ": the samples span " + number_text(span) + " s, more than a week (" +
                                            number_text(kMaxStrokeSeconds) + " s), the longest stroke a replay takes");
  for (size_t i = 0; i < st.events.size(); ++i) {
    const StrokeEvent& e = st.events[i];
    const std::string where = src + ": events[" + std::to_string(i) + "]: ";
    if (!std::isfinite(e.t) || e.t < 0) WB_THROW(where + "t must be a finite time >= 0");
    if (i > 0 && e.t < st.events[i - 1].t)
      WB_THROW(where + "t = " + number_text(e.t) + " is before events[" + std::to_string(i - 1) + "].t = " +
               number_text(st.events[i - 1].t) + " (events must be in time order)");
    if (e.t > st.samples.back().t)
      WB_THROW(where + "t = " + number_text(e.t) + " is after the last sample (t = " +
               number_text(st.samples.back().t) + ")");
  }
}

Stroke parse_stroke_json(std::string_view text, const std::string& source) {
  json root;
  try {
    root = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    const auto [line, col] = line_column(text, e.byte);
    WB_THROW(source + ":" + std::to_string(line) + ":" + std::to_string(col) +
             ": JSON syntax error: " + parse_error_detail(e.what()));
  } catch (const json::exception& e) {
    // Number overflow names the token but not where it is: find it.
    std::string detail = parse_error_detail(e.what());
    std::string at;
    const size_t q = detail.find('\'');
    const size_t q2 = q == std::string::npos ? q : detail.find('\'', q + 1);
    if (q2 != std::string::npos) {
      const size_t pos = text.find(detail.substr(q + 1, q2 - q - 1));
      if (pos != std::string_view::npos) {
        const auto [line, col] = line_column(text, pos + 1);
        at = ":" + std::to_string(line) + ":" + std::to_string(col);
      }
    }
    WB_THROW(source + at + ": JSON error: " + detail);
  }

  Stroke st;
  st.source = source;
  ObjectReader top(root, source, "");
  if (!top.has("format"))
    top.fail("missing key 'format' (expected \"format\": \"" + std::string(kFormatName) + "\"): not a wetbrush stroke file");
  if (top.string("format") != kFormatName)
    top.fail("format is " + root.at("format").dump() + ", expected \"" + kFormatName + "\"", "format");
  {
    const json& v = top.raw("version");
    if (!v.is_number_integer()) top.fail("expected an integer version, found " + json_type_name(v), "version");
    const int64_t version = v.get<int64_t>();
    if (version > kStrokeFormatVersion)
      top.fail("version " + std::to_string(version) + " was written by a newer wetbrush (this build reads version " +
                   std::to_string(kStrokeFormatVersion) + ")",
               "version");
    if (version < 1) top.fail("unknown version " + std::to_string(version), "version");
  }
  top.has("comment");  // free text, ignored

  {
    ObjectReader c(top.raw("canvas"), source, "canvas");
    st.canvas.width = c.integer("width", 1, 65536);
    st.canvas.height = c.integer("height", 1, 65536);
    st.canvas.depth = c.integer_or("depth", 64, 1, 1024);
    if (int64_t(st.canvas.width) * st.canvas.height > kMaxCanvasCells)
      c.fail("canvas " + std::to_string(st.canvas.width) + " x " + std::to_string(st.canvas.height) + " has more than " +
             std::to_string(kMaxCanvasCells) + " cells (16384 x 16384): refused");
    if (c.has("paper_rgb")) st.paper_rgb = c.triple("paper_rgb", 0.0, 1.0);
    if (c.has("tilt")) st.tilt = float(c.number("tilt", 0.0, 90.0));
    if (c.has("ground")) {
      st.ground = ground_from_json(root.at("canvas").at("ground"), source, "canvas.ground");
      const std::string why =
          ground_refusal(*st.ground, st.canvas.width, st.canvas.height, st.canvas.depth, GridParams{}.cell_size);
      if (!why.empty()) c.fail(why + ": refused", "ground");
    }
    c.warn_unknown(st.warnings);
  }
  if (top.has("brush")) st.brush = brush_from_json(root.at("brush"), source, "brush", &st.warnings);
  else st.brush = default_brush(BrushShape::Round);
  if (top.has("paint")) {
    ObjectReader p(root.at("paint"), source, "paint");
    PaintLoad d;
    const auto ryb = p.has("ryb") ? p.triple("ryb", 0.0, 1.0) : std::array<float, 3>{d.ryb[0], d.ryb[1], d.ryb[2]};
    for (int c = 0; c < 3; ++c) st.paint.ryb[c] = ryb[c];
    st.paint.oil = float(p.number_or("oil", d.oil, 0.0, 1.0));
    st.paint.load = float(p.number_or("load", d.load, 0.0, 1.0));
    st.paint.reload_on_pen_down = p.boolean_or("reload_on_pen_down", d.reload_on_pen_down);
    p.warn_unknown(st.warnings);
  }
  if (top.has("simulation")) {
    ObjectReader s(root.at("simulation"), source, "simulation");
    st.dt = s.number_or("dt", st.dt, 1e-4, 0.1);
    st.max_move_per_substep = float(s.number_or("max_move_per_substep", st.max_move_per_substep, 0.1, 100.0));
    st.max_substeps = s.integer_or("max_substeps", st.max_substeps, 1, 1024);
    st.lead_in = s.number_or("lead_in", st.lead_in, 0.0, 5.0);
    st.lead_out = s.number_or("lead_out", st.lead_out, 0.0, 5.0);
    if (s.has("window")) {
      const std::array<float, 3> w = s.triple("window", 8.0, 1024.0);
      for (int i = 0; i < 3; ++i)
        if (w[i] != std::floor(w[i])) s.fail("expected whole cells", "window");
      WB_REQUIRE(w[0] >= 16 && w[1] >= 16, source + ": simulation.window needs X and Y of at least 16 cells");
      st.window = std::array<int, 3>{int(w[0]), int(w[1]), int(w[2])};
    }
    s.warn_unknown(st.warnings);
  }
  read_samples(top.raw("samples"), st);
  if (top.has("events")) read_events(root.at("events"), st);
  top.warn_unknown(st.warnings);
  validate_stroke(st);
  return st;
}

std::string stroke_to_json_string(const Stroke& st) {
  validate_stroke(st);
  json canvas = {{"width", st.canvas.width}, {"height", st.canvas.height}, {"depth", st.canvas.depth}};
  if (st.paper_rgb)
    canvas["paper_rgb"] = {float_for_json((*st.paper_rgb)[0]), float_for_json((*st.paper_rgb)[1]),
                           float_for_json((*st.paper_rgb)[2])};
  if (st.ground) canvas["ground"] = ground_to_json(*st.ground);
  if (st.tilt) canvas["tilt"] = float_for_json(*st.tilt);
  const json paint = {{"ryb", {float_for_json(st.paint.ryb[0]), float_for_json(st.paint.ryb[1]), float_for_json(st.paint.ryb[2])}},
                      {"oil", float_for_json(st.paint.oil)},
                      {"load", float_for_json(st.paint.load)},
                      {"reload_on_pen_down", st.paint.reload_on_pen_down}};
  json sim = {{"dt", st.dt},
              {"max_move_per_substep", float_for_json(st.max_move_per_substep)},
              {"max_substeps", st.max_substeps},
              {"lead_in", st.lead_in},
              {"lead_out", st.lead_out}};
  if (st.window) sim["window"] = {(*st.window)[0], (*st.window)[1], (*st.window)[2]};
  std::string out;
  out += "{\n  \"format\": \"" + std::string(kFormatName) + "\",\n";
  out += "  \"version\": " + std::to_string(kStrokeFormatVersion) + ",\n";
  out += "  \"canvas\": " + canvas.dump() + ",\n";
  out += "  \"brush\": " + brush_to_json(st.brush).dump() + ",\n";
  out += "  \"paint\": " + paint.dump() + ",\n";
  out += "  \"simulation\": " + sim.dump() + ",\n";
  out += "  \"samples\": [\n";
  for (size_t i = 0; i < st.samples.size(); ++i) {
    const PenSample& s = st.samples[i];
    json j = {{"t", s.t},
              {"x", float_for_json(s.x)},
              {"y", float_for_json(s.y)},
              {"pressure", float_for_json(s.pressure)},
              {"tilt_x", float_for_json(s.tilt_x)},
              {"tilt_y", float_for_json(s.tilt_y)},
              {"twist", float_for_json(s.twist)}};
    if (!s.down) j["down"] = false;
    out += "    " + j.dump() + (i + 1 < st.samples.size() ? ",\n" : "\n");
  }
  out += "  ],\n  \"events\": [";
  for (size_t i = 0; i < st.events.size(); ++i) {
    const StrokeEvent& e = st.events[i];
    json j = {{"type", to_string(e.kind)}, {"t", e.t}};
    if (e.kind == StrokeEventKind::Dip) {
      j["ryb"] = {float_for_json(e.ryb[0]), float_for_json(e.ryb[1]), float_for_json(e.ryb[2])};
      j["oil"] = float_for_json(e.oil);
      j["load"] = float_for_json(e.load);
    } else if (e.kind == StrokeEventKind::Wipe) {
      j["fraction"] = float_for_json(e.fraction);
    }
    out += (i == 0 ? "\n    " : ",\n    ") + j.dump();
  }
  out += st.events.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return out;
}

void save_stroke_json(const Stroke& stroke, const std::string& path) {
  write_file_atomic(path, stroke_to_json_string(stroke));
}

Stroke load_stroke(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) WB_THROW("cannot read stroke file '" + path + "': it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) WB_THROW("cannot open stroke file '" + path + "': " + std::strerror(errno));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) WB_THROW("cannot read stroke file '" + path + "'");
  return parse_stroke_text(text, path);
}

Stroke parse_stroke_text(std::string_view text, const std::string& path) {
  // Text only: control bytes other than tab / newline / carriage return mean binary data.
  size_t line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') ++line;
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", c);
      WB_THROW(path + ":" + std::to_string(line) + ": binary data (byte " + hex + " at offset " + std::to_string(i) +
               "): not a stroke file (JSON or MyPaint text dump)");
    }
  }
  size_t first = 0;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") first = 3;  // UTF-8 byte order mark
  while (first < text.size() && std::isspace(static_cast<unsigned char>(text[first]))) ++first;
  if (first == text.size()) WB_THROW(path + ": empty file (no JSON object and no MyPaint events)");
  if (text[first] == '{' || text[first] == '[') return parse_stroke_json(text, path);
  return parse_mypaint_events(text, path);
}

}  // namespace wb
