// Stroke input, MyPaint event dumps (docs/FORMATS.md): one `t x y pressure [xtilt ytilt]`
// line per tablet event, as libmypaint's stroke player reads them. Recorded by drivers,
// so slight overshoots are clamped with a warning; malformed lines are errors at file:line.
#include <cctype>
#include <charconv>
#include <cmath>
#include <vector>

#include "core/exec/error.h"
#include "core/io/json_reader.h"
#include "core/io/stroke.h"

namespace wb {
namespace {

/// MyPaint stores tilt normalised to [-1, 1]; +-1 is taken as +-60 degrees, the range of
/// common pen tablets (Wacom reports about +-60..64 degrees).
constexpr float kMyPaintTiltDeg = 60.f;

/// One clamp kind: how many, and the first line it happened on.
struct ClampCount {
  size_t count = 0;
  size_t first_line = 0;
  void add(size_t line) {
    if (count++ == 0) first_line = line;
  }
};

}  // namespace

Stroke parse_mypaint_events(std::string_view text, const std::string& source) {
  static const char* kColumns[] = {"t", "x", "y", "pressure", "xtilt", "ytilt"};
  Stroke st;
  st.source = source;
  st.brush = default_brush(BrushShape::Round);
  st.paint = PaintLoad{};
  st.paint.reload_on_pen_down = true;

  ClampCount pressure_clamped, tilt_clamped, off_canvas, same_time;
  size_t last_line = 0;
  size_t line_no = 0;
  size_t pos = 0;
  std::vector<std::string_view> cols;
  while (pos < text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);

    cols.clear();
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      if (j > i) cols.push_back(line.substr(i, j - i));
      i = j;
    }
    if (cols.empty()) continue;
    const std::string where = source + ":" + std::to_string(line_no) + ": ";
    if (cols.size() != 4 && cols.size() != 6)
      WB_THROW(where + "expected 4 columns (t x y pressure) or 6 (t x y pressure xtilt ytilt), found " +
               std::to_string(cols.size()));

    double v[6] = {0, 0, 0, 0, 0, 0};
    for (size_t c = 0; c < cols.size(); ++c) {
      const std::string_view tok = cols[c];
      const char* b = tok.data();
      const char* e = b + tok.size();
      if (b < e && *b == '+') ++b;  // from_chars rejects a leading '+'
      auto r = std::from_chars(b, e, v[c]);
      if (r.ec == std::errc::result_out_of_range)
        WB_THROW(where + "column " + std::to_string(c + 1) + " (" + kColumns[c] + "): '" + std::string(tok) +
                 "' is out of range");
      if (r.ec != std::errc() || r.ptr != e)
        WB_THROW(where + "column " + std::to_string(c + 1) + " (" + kColumns[c] + "): '" + std::string(tok) +
                 "' is not a number");
      if (!std::isfinite(v[c]) || std::fabs(v[c]) > kAbsurdValue)
        WB_THROW(where + "column " + std::to_string(c + 1) + " (" + kColumns[c] + "): '" + std::string(tok) +
                 "' is not a finite, plausible value (|v| <= 1e7)");
    }

    PenSample s;
    s.t = v[0];
    s.x = float(v[1]);
    s.y = float(v[2]);
    double p = v[3];
    if (p < 0.0 || p > 1.0) {
      pressure_clamped.add(line_no);
      p = p < 0.0 ? 0.0 : 1.0;
    }
    s.pressure = float(p);
    s.down = s.pressure > 0.f;
    if (cols.size() == 6) {
      for (int c = 4; c < 6; ++c) {
        if (v[c] < -1.0 || v[c] > 1.0) {
          tilt_clamped.add(line_no);
          v[c] = v[c] < -1.0 ? -1.0 : 1.0;
        }
      }
      s.tilt_x = float(v[4]) * kMyPaintTiltDeg;
      s.tilt_y = float(v[5]) * kMyPaintTiltDeg;
    }
    const float w = float(st.canvas.width), h = float(st.canvas.height);
    if (s.x < 0.f || s.y < 0.f || s.x > w || s.y > h) {
      off_canvas.add(line_no);
      s.x = s.x < 0.f ? 0.f : (s.x > w ? w : s.x);
      s.y = s.y < 0.f ? 0.f : (s.y > h ? h : s.y);
    }

    if (!st.samples.empty()) {
      const double prev = st.samples.back().t;
      if (s.t < prev)
        WB_THROW(where + "t = " + number_text(s.t) + " is earlier than the previous event's t = " + number_text(prev) +
                 " (line " +
                 std::to_string(last_line) + "): events must be in time order");
      if (s.t == prev) {
        // Drivers emit bursts with one timestamp; the latest state wins.
        same_time.add(line_no);
        st.samples.back() = s;
        last_line = line_no;
        continue;
      }
    }
    st.samples.push_back(s);
    last_line = line_no;
  }

  if (st.samples.empty())
    WB_THROW(source + ": no events (a MyPaint dump has one 't x y pressure' line per event)");

  // Tablet clocks are often absolute: the stroke starts at t = 0.
  const double t0 = st.samples.front().t;
  for (PenSample& s : st.samples) s.t -= t0;

  const auto warn = [&](const ClampCount& c, const std::string& what) {
    if (c.count)
      st.warnings.push_back(source + ":" + std::to_string(c.first_line) + ": " + what + " (" + std::to_string(c.count) +
                            " events, first here)");
  };
  warn(pressure_clamped, "pressure outside [0, 1] clamped");
  warn(tilt_clamped, "xtilt/ytilt outside [-1, 1] clamped");
  warn(off_canvas, "position off the " + std::to_string(st.canvas.width) + " x " + std::to_string(st.canvas.height) +
                       " canvas clamped to its edge");
  warn(same_time, "event with the same t as the previous one replaces it");
  bool any_down = false;
  for (const PenSample& s : st.samples) any_down = any_down || s.down;
  if (!any_down) st.warnings.push_back(source + ": every event has pressure 0 (pen up): the brush never touches");

  validate_stroke(st);
  return st;
}

}  // namespace wb
