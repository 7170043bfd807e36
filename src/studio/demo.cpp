#include "studio/demo.h"

#include <QApplication>
#include <QElapsedTimer>
#include <QPointingDevice>
#include <QTabletEvent>
#include <QThread>

#include "studio/canvas_view.h"

namespace wb::studio {
namespace {

const QPointingDevice* stylus() {
  static QPointingDevice* dev = [] {
    auto* d = new QPointingDevice("wetbrush synthetic stylus", 1, QInputDevice::DeviceType::Stylus,
                                  QPointingDevice::PointerType::Pen,
                                  QInputDevice::Capability::Position | QInputDevice::Capability::Pressure |
                                      QInputDevice::Capability::XTilt | QInputDevice::Capability::YTilt |
                                      QInputDevice::Capability::Rotation,
                                  1, 3);
    return d;
  }();
  return dev;
}

void send(CanvasView* view, QEvent::Type type, const ScriptPoint& p, Qt::MouseButton button, Qt::MouseButtons buttons) {
  const QPointF w = view->to_widget(p.canvas);
  QTabletEvent e(type, stylus(), w, view->mapToGlobal(w), qreal(p.pressure), p.tilt_x, p.tilt_y, 0.0, p.rotation,
                 0.0, Qt::NoModifier, button, buttons);
  QApplication::sendEvent(view, &e);
}

void pause_ms(int ms) {
  QElapsedTimer t;
  t.start();
  while (t.elapsed() < ms) {
    QApplication::processEvents(QEventLoop::AllEvents, 1);
    QThread::usleep(500);
  }
}

}  // namespace

void tablet_stroke(CanvasView* view, const std::vector<ScriptPoint>& points, int interval_ms) {
  if (points.empty()) return;
  send(view, QEvent::TabletPress, points.front(), Qt::LeftButton, Qt::LeftButton);
  for (size_t i = 1; i < points.size(); ++i) {
    pause_ms(interval_ms);
    send(view, QEvent::TabletMove, points[i], Qt::NoButton, Qt::LeftButton);
  }
  pause_ms(interval_ms);
  send(view, QEvent::TabletRelease, points.back(), Qt::LeftButton, Qt::NoButton);
}

std::vector<ScriptPoint> line_points(QPointF a, QPointF b, int n, float pressure, float tilt_x, float tilt_y) {
  std::vector<ScriptPoint> pts;
  for (int i = 0; i < n; ++i) {
    const double s = n > 1 ? double(i) / (n - 1) : 0.0;
    pts.push_back({a + (b - a) * s, pressure, tilt_x, tilt_y, 0.f});
  }
  return pts;
}

}  // namespace wb::studio

#include <cmath>
#include <utility>

#include "studio/main_window.h"

namespace wb::studio {

double run_demo_painting(MainWindow& w) {
  CanvasView* v = w.view();
  const QSize c = v->canvas_size();
  const double W = c.width(), H = c.height();
  struct Pass {
    int well;
    double y;
    double amp;
    float pressure;
    float tilt;
  };
  // Well 0 and well 2 of the default palette; the third stroke crosses the wet first one.
  const Pass passes[] = {{0, 0.40, 0.06, 0.6f, 20.f}, {2, 0.55, 0.08, 0.75f, -15.f}, {0, 0.66, 0.05, 0.5f, 25.f}};
  QElapsedTimer pen;
  double pen_s = 0.0;
  for (const Pass& p : passes) {
    PaintLoad paint = w.paint_panel()->current_paint();
    const QColor col = w.paint_panel()->well_color(p.well);
    const auto ryb = qcolor_to_ryb(col);
    for (int k = 0; k < 3; ++k) paint.ryb[k] = ryb[k];
    w.clean_brush();
    w.dip(paint);
    std::vector<ScriptPoint> pts;
    const int n = 60;
    for (int i = 0; i < n; ++i) {
      const double s = double(i) / (n - 1);
      const double x = W * (0.30 + 0.4 * s);
      const double y = H * (p.y + p.amp * std::sin(s * 6.28318 * 1.1));
      const float pr = p.pressure * float(0.6 + 0.4 * std::sin(s * 3.14159));
      pts.push_back({QPointF(x, y), pr, p.tilt, 0.f, 0.f});
    }
    pen.start();
    tablet_stroke(v, pts, 16);
    pen_s += pen.elapsed() / 1000.0;
    w.settle();
  }
  return pen_s;
}

void paint_loop_stroke(MainWindow& w, int k) {
  const QSize c = w.view()->canvas_size();
  const double W = c.width(), H = c.height();
  const double y = H * (0.2 + 0.15 * (k % 5));
  QPointF a(W * 0.15, y), b(W * 0.85, y);
  if (k % 2) std::swap(a, b);
  w.dip(w.paint_panel()->current_paint());
  tablet_stroke(w.view(), line_points(a, b, 48, 0.6f, 10.f, 0.f), 20);
  w.settle();
}

}  // namespace wb::studio
