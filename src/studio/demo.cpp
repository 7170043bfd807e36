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

/// Sends a tablet event stamped `ms` (the script's time of it, as a tablet stamps its samples).
void send(CanvasView* view, QEvent::Type type, const ScriptPoint& p, Qt::MouseButton button, Qt::MouseButtons buttons,
          quint64 ms) {
  const QPointF w = view->to_widget(p.canvas);
  QTabletEvent e(type, stylus(), w, view->mapToGlobal(w), qreal(p.pressure), p.tilt_x, p.tilt_y, 0.0, p.rotation,
                 0.0, Qt::NoModifier, button, buttons);
  e.setTimestamp(ms);
  QApplication::sendEvent(view, &e);
}

/// Milliseconds on the steady clock (never 0: a timestamp of 0 is none).
quint64 clock_ms() {
  static QElapsedTimer clock = [] {
    QElapsedTimer t;
    t.start();
    return t;
  }();
  return quint64(clock.elapsed()) + 1;
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
  // The samples are stamped as the script moves the pen, interval_ms apart, however late a
  // loaded machine delivers them.
  const quint64 t0 = clock_ms();
  send(view, QEvent::TabletPress, points.front(), Qt::LeftButton, Qt::LeftButton, t0);
  for (size_t i = 1; i < points.size(); ++i) {
    pause_ms(interval_ms);
    send(view, QEvent::TabletMove, points[i], Qt::NoButton, Qt::LeftButton, t0 + quint64(i) * quint64(interval_ms));
  }
  pause_ms(interval_ms);
  send(view, QEvent::TabletRelease, points.back(), Qt::LeftButton, Qt::NoButton,
       t0 + quint64(points.size()) * quint64(interval_ms));
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

DemoTimes run_demo_painting(MainWindow& w, bool short_demo) {
  // A small painting on linen, 8 x 6 cm: two colours put out on the palette and mixed there, a
  // stroke of the mix, one of a well's paint across it while it is wet, and a light pass of a
  // lightly loaded brush that catches the weave.
  const int W = 400, H = 300;
  // The script loads the brush itself (the palette's mix, then Clean and Dip): with *Reload each
  // stroke* on, every press would clean it and load the selected well instead.
  w.paint_panel()->set_reload_each_stroke(false);
  w.new_canvas(W, H, QColor(236, 229, 212), CanvasGround::of(Weave::Linen));
  w.settle();
  CanvasView* v = w.view();
  v->fit();
  PalettePanel* pal = w.palette();
  const QSize ps = pal->view()->canvas_size();
  const double pw = ps.width(), ph = ps.height();
  const auto well = [&](int i, float load) {
    PaintLoad paint = w.paint_panel()->current_paint();
    const auto ryb = qcolor_to_ryb(w.paint_panel()->well_color(i));
    for (int k = 0; k < 3; ++k) paint.ryb[k] = ryb[k];
    paint.load = load;
    return paint;
  };
  if (!short_demo) {
    pal->put_paint(QPointF(0.35 * pw, 0.5 * ph), well(0, 1.f));
    pal->put_paint(QPointF(0.65 * pw, 0.5 * ph), well(2, 1.f));
  }
  w.clean_brush();
  w.settle();
  QElapsedTimer pen;
  DemoTimes t;
  const auto timed = [&](CanvasView* view, const std::vector<ScriptPoint>& pts) {
    pen.start();
    tablet_stroke(view, pts, 16);
    t.pen_s += pen.elapsed() / 1000.0;
    w.settle(true);  // the frames of the catching up reach the screen as they come
    (view == v ? t.canvas_s : t.palette_s) += pen.elapsed() / 1000.0;
  };
  // Scrubbed together on the palette: the brush comes away with the mix.
  for (int k = 0; k < (short_demo ? 0 : 3); ++k) {
    const double y = ph * (0.5 + 0.04 * (k - 1));
    timed(pal->view(), line_points(QPointF(pw * (k % 2 ? 0.8 : 0.2), y), QPointF(pw * (k % 2 ? 0.2 : 0.8), y), 40,
                                   0.6f, k % 2 ? -15.f : 15.f));
  }
  struct Pass {
    int well;      ///< -1: the brush as it comes from the palette
    float load;
    double y, amp;
    float pressure, tilt;
  };
  const Pass passes[] = {{-1, 0.f, 0.38, 0.06, 0.6f, 20.f}, {2, 1.f, 0.52, 0.08, 0.75f, -15.f}, {0, 0.3f, 0.68, 0.04, 0.2f, 25.f}};
  for (const Pass& p : passes) {
    if (short_demo && p.well != 2) continue;
    if (p.well >= 0) {
      w.clean_brush();
      w.dip(well(p.well, p.load));
    }
    std::vector<ScriptPoint> pts;
    const int n = 60;
    for (int i = 0; i < n; ++i) {
      const double s = double(i) / (n - 1);
      const double x = W * (0.15 + 0.7 * s);
      const double y = H * (p.y + p.amp * std::sin(s * 6.28318 * 1.1));
      const float pr = p.pressure * float(0.6 + 0.4 * std::sin(s * 3.14159));
      pts.push_back({QPointF(x, y), pr, p.tilt, 0.f, 0.f});
    }
    timed(v, pts);
  }
  return t;
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
