// Scripted input for the studio: synthesised tablet strokes through the real event path
// (QTabletEvent -> CanvasView -> session clock -> simulation), used by the tests, by the
// README screenshot and by the frame-rate measurement.
#pragma once
#include <QPointF>
#include <vector>

namespace wb::studio {

class CanvasView;

struct ScriptPoint {
  QPointF canvas;        ///< canvas cells
  float pressure = 0.5f;
  float tilt_x = 0.f, tilt_y = 0.f, rotation = 0.f;
};

/// Sends a press, moves and a release as QTabletEvents at the widget positions of the canvas
/// points, `interval_ms` apart (events are processed between points, so time advances).
void tablet_stroke(CanvasView* view, const std::vector<ScriptPoint>& points, int interval_ms = 8);

/// A straight line of `n` points from a to b at constant pressure.
std::vector<ScriptPoint> line_points(QPointF a, QPointF b, int n, float pressure, float tilt_x = 0.f,
                                     float tilt_y = 0.f);

}  // namespace wb::studio

namespace wb::studio {
class MainWindow;
/// Wall seconds of a scripted painting: the pen down, and each surface's strokes from the pen's
/// press until its simulation has caught up (so a rate is that surface's own).
struct DemoTimes {
  double pen_s = 0.0;
  double canvas_s = 0.0, palette_s = 0.0;
};
/// A small scripted painting on linen: two wells' paint put out on the palette and mixed there,
/// three curved strokes (the mix, a well's paint, a dry-brush pass) with varying pressure and tilt
/// (the README screenshot and the frame-rate measurement). `short_demo`: the well's stroke alone,
/// nothing on the palette (a test that the demo runs).
DemoTimes run_demo_painting(MainWindow& w, bool short_demo = false);
/// Stroke k of an endless scripted session (`--paint-loop`, the autosave and recovery test): a
/// dip, then a straight stroke of about a second across row k mod 5 of the canvas, alternating in
/// direction. Returns once the simulation has caught up with it.
void paint_loop_stroke(MainWindow& w, int k);
}  // namespace wb::studio
