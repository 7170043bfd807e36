#include "studio/canvas_view.h"

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QTabletEvent>
#include <QTransform>
#include <QWheelEvent>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace wb::studio {
namespace {

const char* kVertexShader = R"(
attribute vec2 pos;
uniform vec3 row0;
uniform vec3 row1;
uniform vec2 size;
varying vec2 uv;
void main() {
  vec3 p = vec3(pos * size, 1.0);
  gl_Position = vec4(dot(row0, p), dot(row1, p), 0.0, 1.0);
  uv = pos;
})";

const char* kFragmentShader = R"(
uniform sampler2D tex;
varying vec2 uv;
void main() { gl_FragColor = texture2D(tex, uv); })";

}  // namespace

CanvasView::CanvasView(QWidget* parent) : QOpenGLWidget(parent) {
  setMouseTracking(true);
  setFocusPolicy(Qt::StrongFocus);
  setAttribute(Qt::WA_TabletTracking);
  setMinimumSize(320, 240);
}

CanvasView::~CanvasView() {
  makeCurrent();
  if (texture_) glDeleteTextures(1, &texture_);
  quad_.destroy();
  doneCurrent();
}

void CanvasView::set_canvas_size(int w, int h) {
  canvas_w_ = std::max(1, w);
  canvas_h_ = std::max(1, h);
  texture_stale_ = true;
  fitted_ = false;
  fit();
}

void CanvasView::set_view(QPointF center, float zoom, float rotation_deg) {
  center_ = center;
  zoom_ = std::clamp(zoom, 1.f / 64.f, 64.f);
  rotation_deg_ = std::fmod(rotation_deg, 360.f);
  update();
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

QPointF CanvasView::to_widget(QPointF c) const {
  QTransform t;
  t.translate(width() * 0.5, height() * 0.5);
  t.rotate(rotation_deg_);
  t.scale(zoom_, zoom_);
  t.translate(-center_.x(), -center_.y());
  return t.map(c);
}

QPointF CanvasView::to_canvas(QPointF w) const {
  QTransform t;
  t.translate(width() * 0.5, height() * 0.5);
  t.rotate(rotation_deg_);
  t.scale(zoom_, zoom_);
  t.translate(-center_.x(), -center_.y());
  return t.inverted().map(w);
}

void CanvasView::initializeGL() {
  initializeOpenGLFunctions();
  program_.addShaderFromSourceCode(QOpenGLShader::Vertex, kVertexShader);
  program_.addShaderFromSourceCode(QOpenGLShader::Fragment, kFragmentShader);
  program_.bindAttributeLocation("pos", 0);
  program_.link();
  const GLfloat quad[] = {0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 1.f};
  quad_.create();
  quad_.bind();
  quad_.allocate(quad, sizeof quad);
  quad_.release();
  glGenTextures(1, &texture_);
  texture_stale_ = true;
}

void CanvasView::resizeGL(int, int) {
  if (!fitted_) {
    fitted_ = true;
    fit();
  }
}

void CanvasView::paintGL() {
  // Upload what changed since the last frame: the whole image once, then only the dirty rectangle.
  QRect dirty;
  if (source_) dirty = source_(image_);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (!image_.isNull() && (texture_stale_ || dirty == image_.rect())) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, image_.width(), image_.height(), 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 image_.constBits());
    texture_stale_ = false;
  } else if (!image_.isNull() && !dirty.isEmpty()) {
    glPixelStorei(GL_UNPACK_ROW_LENGTH, image_.width());
    glTexSubImage2D(GL_TEXTURE_2D, 0, dirty.x(), dirty.y(), dirty.width(), dirty.height(), GL_RGBA, GL_UNSIGNED_BYTE,
                    image_.constScanLine(dirty.y()) + dirty.x() * 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  }
  // Cells stay crisp from 1:1 up; smaller zooms are filtered.
  const GLint filter = zoom_ >= 1.f ? GL_NEAREST : GL_LINEAR;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  glClearColor(0.16f, 0.16f, 0.17f, 1.f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (!image_.isNull()) {
    // canvas cells -> widget pixels -> normalised device coordinates
    QTransform t;
    t.translate(width() * 0.5, height() * 0.5);
    t.rotate(rotation_deg_);
    t.scale(zoom_, zoom_);
    t.translate(-center_.x(), -center_.y());
    const QTransform ndc(2.0 / width(), 0, 0, -2.0 / height(), -1.0, 1.0);
    const QTransform m = t * ndc;
    program_.bind();
    program_.setUniformValue("row0", QVector3D(m.m11(), m.m21(), m.m31()));
    program_.setUniformValue("row1", QVector3D(m.m12(), m.m22(), m.m32()));
    program_.setUniformValue("size", QVector2D(image_.width(), image_.height()));
    program_.setUniformValue("tex", 0);
    glActiveTexture(GL_TEXTURE0);
    quad_.bind();
    program_.enableAttributeArray(0);
    program_.setAttributeBuffer(0, GL_FLOAT, 0, 2);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    program_.disableAttributeArray(0);
    quad_.release();
    program_.release();
  }
  glBindTexture(GL_TEXTURE_2D, 0);

  // Overlay: the brush footprint under the cursor.
  if (cursor_.x() >= 0) {
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing);
    p.setPen(QPen(QColor(255, 255, 255, 160), 1.0));
    const double r = cursor_radius_ * zoom_;
    p.drawEllipse(cursor_, r, r);
    p.setPen(QPen(QColor(0, 0, 0, 160), 1.0));
    p.drawEllipse(cursor_, r + 1, r + 1);
  }
  ++frames_;
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
  cursor_ = e->position();
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
  update();
}

void CanvasView::mousePressEvent(QMouseEvent* e) {
  setFocus();
  cursor_ = e->position();
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
  update();
}

void CanvasView::mouseMoveEvent(QMouseEvent* e) {
  cursor_ = e->position();
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
  update();
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
  update();
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
    default: QOpenGLWidget::keyPressEvent(e);
  }
}

}  // namespace wb::studio
