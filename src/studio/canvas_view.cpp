#include "studio/canvas_view.h"

#include <QGuiApplication>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QPainter>
#include <QTabletEvent>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>

#include "studio/canvas_surface.h"

namespace wb::studio {

std::optional<ViewKind> parse_view_kind(const QString& name) {
  if (name == "auto") return ViewKind::Auto;
  if (name == "gl") return ViewKind::Gl;
  if (name == "raster") return ViewKind::Raster;
  return std::nullopt;
}

const char* view_kind_name(ViewKind k) {
  switch (k) {
    case ViewKind::Gl: return "gl";
    case ViewKind::Raster: return "raster";
    default: return "auto";
  }
}

bool opengl_available() {
  static const bool ok = [] {
    // Platforms that draw into memory only do not compose widgets through OpenGL, which
    // QOpenGLWidget needs ("not supported on this platform", then a crash) even where a context
    // can be made: the offscreen platform makes one through GLX when there is a display.
    const QString platform = QGuiApplication::platformName();
    for (const char* memory_only : {"offscreen", "minimal", "linuxfb", "vnc"})
      if (platform == QLatin1String(memory_only)) return false;
    QOpenGLContext context;
    if (!context.create()) return false;
    QOffscreenSurface surface;
    surface.setFormat(context.format());
    surface.create();
    if (!surface.isValid() || !context.makeCurrent(&surface)) return false;
    context.doneCurrent();
    return true;
  }();
  return ok;
}

CanvasView::CanvasView(ViewKind kind, QWidget* parent) : QWidget(parent) {
  kind_ = kind != ViewKind::Auto ? kind : opengl_available() ? ViewKind::Gl : ViewKind::Raster;
  setMouseTracking(true);
  setFocusPolicy(Qt::StrongFocus);
  setAttribute(Qt::WA_TabletTracking);
  setMinimumSize(320, 240);
  if (kind_ == ViewKind::Gl)
    surface_ = new GlSurface(*this);
  else
    surface_ = new RasterSurface(*this);
}

CanvasView::~CanvasView() = default;  // the surface is a child widget

QOpenGLWidget* CanvasView::gl_widget() const { return dynamic_cast<GlSurface*>(surface_); }

void CanvasView::frame_ready() { pull(); }

void CanvasView::pull() {
  if (!source_) return;
  FrameUpdate u = source_(image_);
  if (u.dirty.isEmpty()) return;
  awaiting_.insert(awaiting_.end(), u.input_times.begin(), u.input_times.end());
  const QRect shown =
      canvas_transform().mapRect(QRectF(u.dirty)).toAlignedRect().adjusted(-1, -1, 1, 1).intersected(rect());
  // Pixels out of sight are never drawn: their pen events are as much on screen as they will be.
  if (shown.isEmpty() || !isVisible()) time_inputs();
  surface_->image_changed(u.dirty, isVisible() ? shown : QRect());
}

void CanvasView::presented(int64_t pixels) {
  ++frames_;
  pixels_ += pixels;
  time_inputs();
}

void CanvasView::time_inputs() {
  if (awaiting_.empty()) return;
  const double now = wall_now();
  for (const InputTiming& t : awaiting_) latency_.add(t, now);
  awaiting_.clear();
}

void CanvasView::set_canvas_size(int w, int h) {
  canvas_w_ = std::max(1, w);
  canvas_h_ = std::max(1, h);
  fitted_ = false;
  fit();
}

void CanvasView::set_view(QPointF center, float zoom, float rotation_deg) {
  center_ = center;
  zoom_ = std::clamp(zoom, 1.f / 64.f, 64.f);
  rotation_deg_ = std::fmod(rotation_deg, 360.f);
  surface_->widget()->update();
  Q_EMIT viewChanged();
}

void CanvasView::fit() {
  const float z = std::min(float(width()) / canvas_w_, float(height()) / canvas_h_) * 0.95f;
  set_view(QPointF(canvas_w_ * 0.5, canvas_h_ * 0.5), z > 0 ? z : 1.f, 0.f);
}

void CanvasView::zoom_by(float factor, QPointF anchor) {
  const QPointF c = to_canvas(anchor);
  const float z = std::clamp(zoom_ * factor, 1.f / 64.f, 64.f);
  // Keep the canvas point under the anchor in place.
  zoom_ = z;
  const QPointF moved = to_canvas(anchor);
  set_view(center_ + (c - moved), z, rotation_deg_);
}

QTransform CanvasView::canvas_transform() const {
  QTransform t;
  t.translate(width() * 0.5, height() * 0.5);
  t.rotate(rotation_deg_);
  t.scale(zoom_, zoom_);
  t.translate(-center_.x(), -center_.y());
  return t;
}

QPointF CanvasView::to_widget(QPointF c) const { return canvas_transform().map(c); }

QPointF CanvasView::to_canvas(QPointF w) const { return canvas_transform().inverted().map(w); }

void CanvasView::resizeEvent(QResizeEvent*) {
  surface_->widget()->setGeometry(rect());
  if (!fitted_ && width() > 0 && height() > 0) {
    fitted_ = true;
    fit();
  }
}

QRect CanvasView::cursor_rect(QPointF pos) const {
  if (pos.x() < 0) return {};
  const double r = cursor_radius_ * zoom_ + 3.0;
  return QRectF(pos.x() - r, pos.y() - r, 2 * r, 2 * r).toAlignedRect();
}

void CanvasView::move_cursor(QPointF pos) {
  const QRect before = cursor_rect(cursor_);
  cursor_ = pos;
  surface_->widget()->update(before);
  surface_->widget()->update(cursor_rect(cursor_));
}

void CanvasView::paint_overlay(QPainter& p) const {
  // The brush footprint under the cursor.
  if (cursor_.x() < 0) return;
  p.setRenderHint(QPainter::Antialiasing);
  p.setPen(QPen(QColor(255, 255, 255, 160), 1.0));
  const double r = cursor_radius_ * zoom_;
  p.drawEllipse(cursor_, r, r);
  p.setPen(QPen(QColor(0, 0, 0, 160), 1.0));
  p.drawEllipse(cursor_, r + 1, r + 1);
}

PenInput CanvasView::input_at(QPointF pos, float pressure, float tilt_x, float tilt_y, float twist) const {
  const QPointF c = to_canvas(pos);
  PenInput p;
  p.x = float(c.x());
  p.y = float(c.y());
  p.pressure = std::pow(std::clamp(pressure, 0.f, 1.f), gamma_);
  // Tilt and twist are measured against the screen: turn them into the canvas frame.
  const float a = -rotation_deg_ * 3.14159265f / 180.f;
  const float tx = std::tan(std::clamp(tilt_x, -80.f, 80.f) * 3.14159265f / 180.f);
  const float ty = std::tan(std::clamp(tilt_y, -80.f, 80.f) * 3.14159265f / 180.f);
  p.tilt_x = std::atan(std::cos(a) * tx - std::sin(a) * ty) * 180.f / 3.14159265f;
  p.tilt_y = std::atan(std::sin(a) * tx + std::cos(a) * ty) * 180.f / 3.14159265f;
  p.twist = twist - rotation_deg_;
  return p;
}

double CanvasView::event_time(const QInputEvent* e, bool press) {
  const double now = wall_now();
  const quint64 ms = e->timestamp();
  if (press) last_stamp_ = 0;
  // No timestamps, or one that goes back (another device, a clock that wrapped): the arrival.
  if (ms == 0 || (last_stamp_ != 0 && ms < last_stamp_)) {
    last_stamp_ = 0;
    return now;
  }
  const double offset = now - double(ms) / 1000.0;
  stamp_offset_ = last_stamp_ == 0 ? offset : std::min(stamp_offset_, offset);
  last_stamp_ = ms;
  return double(ms) / 1000.0 + stamp_offset_;
}

void CanvasView::tabletEvent(QTabletEvent* e) {
  const PenInput in = input_at(e->position(), float(e->pressure()), float(e->xTilt()), float(e->yTilt()),
                               float(e->rotation()));
  switch (e->type()) {
    case QEvent::TabletPress:
      if (e->button() == Qt::LeftButton && !pen_down_ && (e->modifiers() & Qt::AltModifier)) {
        Q_EMIT pickColor(to_canvas(e->position()));
      } else if (e->button() == Qt::LeftButton && !pen_down_ && place_paint_ && (e->modifiers() & Qt::ControlModifier)) {
        Q_EMIT placePaint(to_canvas(e->position()));
      } else if (e->button() == Qt::LeftButton && !pen_down_) {
        pen_down_ = tablet_down_ = true;
        last_input_ = in;
        Q_EMIT penPress(in, event_time(e, true));
      }
      break;
    case QEvent::TabletMove:
      if (tablet_down_) {
        last_input_ = in;
        Q_EMIT penMove(in, event_time(e, false));
      }
      break;
    case QEvent::TabletRelease:
      if (tablet_down_) {
        // The release event reports no pressure: the stroke ends as it was last pressed.
        PenInput r = in;
        r.pressure = last_input_.pressure;
        pen_down_ = tablet_down_ = false;
        Q_EMIT penRelease(r, event_time(e, false));
      }
      break;
    default: break;
  }
  e->accept();
  move_cursor(e->position());
}

void CanvasView::mousePressEvent(QMouseEvent* e) {
  setFocus();
  if (e->button() == Qt::RightButton && !pen_down_) {
    light_drag_ = true;
    light_anchor_ = e->position();
  } else if (e->button() == Qt::MiddleButton || (e->button() == Qt::LeftButton && (e->modifiers() & Qt::ShiftModifier))) {
    panning_ = true;
    pan_anchor_ = e->position();
  } else if (e->button() == Qt::LeftButton && !pen_down_ && (e->modifiers() & Qt::AltModifier)) {
    Q_EMIT pickColor(to_canvas(e->position()));
  } else if (e->button() == Qt::LeftButton && !pen_down_ && place_paint_ && (e->modifiers() & Qt::ControlModifier)) {
    Q_EMIT placePaint(to_canvas(e->position()));
  } else if (e->button() == Qt::LeftButton && !pen_down_) {
    pen_down_ = true;
    const PenInput in = input_at(e->position(), mouse_pressure_, 0.f, 0.f, 0.f);
    last_input_ = in;
    Q_EMIT penPress(in, event_time(e, true));
  }
  move_cursor(e->position());
}

void CanvasView::mouseMoveEvent(QMouseEvent* e) {
  if (light_drag_) {
    Q_EMIT lightDrag(e->position() - light_anchor_, false);
  } else if (panning_) {
    const QPointF d = to_canvas(pan_anchor_) - to_canvas(e->position());
    pan_anchor_ = e->position();
    set_view(center_ + d, zoom_, rotation_deg_);
  } else if (pen_down_ && !tablet_down_) {
    const PenInput in = input_at(e->position(), mouse_pressure_, 0.f, 0.f, 0.f);
    last_input_ = in;
    Q_EMIT penMove(in, event_time(e, false));
  }
  move_cursor(e->position());
}

void CanvasView::mouseReleaseEvent(QMouseEvent* e) {
  if (light_drag_ && e->button() == Qt::RightButton) {
    light_drag_ = false;
    Q_EMIT lightDrag(e->position() - light_anchor_, true);
  } else if (panning_) {
    panning_ = false;
  } else if (pen_down_ && !tablet_down_ && e->button() == Qt::LeftButton) {
    pen_down_ = false;
    Q_EMIT penRelease(input_at(e->position(), mouse_pressure_, 0.f, 0.f, 0.f), event_time(e, false));
  }
  move_cursor(e->position());
}

void CanvasView::wheelEvent(QWheelEvent* e) {
  const float steps = float(e->angleDelta().y()) / 120.f;
  if (e->modifiers() & Qt::ControlModifier)
    set_view(center_, zoom_, rotation_deg_ + 15.f * steps);
  else
    zoom_by(std::pow(1.25f, steps), e->position());
  e->accept();
}

void CanvasView::keyPressEvent(QKeyEvent* e) {
  switch (e->key()) {
    case Qt::Key_1: set_view(center_, 1.f, rotation_deg_); break;  // 1:1, one pixel per cell
    case Qt::Key_0: fit(); break;
    case Qt::Key_Plus:
    case Qt::Key_Equal: zoom_by(1.25f, QPointF(width() * 0.5, height() * 0.5)); break;
    case Qt::Key_Minus: zoom_by(0.8f, QPointF(width() * 0.5, height() * 0.5)); break;
    case Qt::Key_R: set_view(center_, zoom_, rotation_deg_ + ((e->modifiers() & Qt::ShiftModifier) ? -15.f : 15.f)); break;
    default: QWidget::keyPressEvent(e);
  }
}

}  // namespace wb::studio
