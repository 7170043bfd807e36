#include "studio/canvas_surface.h"

#include <QPaintEvent>
#include <QPainter>

#include "studio/canvas_view.h"

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

const QColor kBackground = QColor::fromRgbF(0.16f, 0.16f, 0.17f);

/// Sets up a surface as a child that fills its view and leaves every input to it.
void as_surface(QWidget* w) {
  w->setAttribute(Qt::WA_TransparentForMouseEvents);
  w->setFocusPolicy(Qt::NoFocus);
}

}  // namespace

// --- OpenGL ---------------------------------------------------------------------------------

GlSurface::GlSurface(CanvasView& view) : QOpenGLWidget(&view), view_(view) {
  as_surface(this);
  // The window swaps for all its OpenGL children at once: a frame is this surface's only when
  // it painted since the last swap.
  connect(this, &QOpenGLWidget::frameSwapped, this, [this] {
    if (!painted_) return;
    painted_ = false;
    view_.presented(int64_t(width()) * height());
  });
}

GlSurface::~GlSurface() {
  makeCurrent();
  if (texture_) glDeleteTextures(1, &texture_);
  quad_.destroy();
  doneCurrent();
}

void GlSurface::image_changed(const QRect& cells, const QRect& shown) {
  upload_ |= cells;
  // paintGL takes frames itself and draws the whole widget: no second frame for them.
  if (!painting_ && !shown.isEmpty()) update();
}

void GlSurface::initializeGL() {
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
  texture_size_ = QSize();
}

void GlSurface::paintGL() {
  painting_ = true;
  view_.pull();
  painting_ = false;
  const QImage& image = view_.image();
  // Upload what changed since the last frame: the whole image once, then only the dirty rectangle.
  glBindTexture(GL_TEXTURE_2D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (!image.isNull() && (texture_size_ != image.size() || upload_.contains(image.rect()))) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, image.width(), image.height(), 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 image.constBits());
    texture_size_ = image.size();
  } else if (const QRect dirty = upload_ & image.rect(); !image.isNull() && !dirty.isEmpty()) {
    glPixelStorei(GL_UNPACK_ROW_LENGTH, image.width());
    glTexSubImage2D(GL_TEXTURE_2D, 0, dirty.x(), dirty.y(), dirty.width(), dirty.height(), GL_RGBA, GL_UNSIGNED_BYTE,
                    image.constScanLine(dirty.y()) + dirty.x() * 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  }
  upload_ = QRect();
  // Cells stay crisp from 1:1 up; smaller zooms are filtered.
  const GLint filter = view_.zoom() >= 1.f ? GL_NEAREST : GL_LINEAR;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  glClearColor(kBackground.redF(), kBackground.greenF(), kBackground.blueF(), 1.f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (!image.isNull()) {
    // canvas cells -> widget pixels -> normalised device coordinates
    const QTransform ndc(2.0 / width(), 0, 0, -2.0 / height(), -1.0, 1.0);
    const QTransform m = view_.canvas_transform() * ndc;
    program_.bind();
    program_.setUniformValue("row0", QVector3D(m.m11(), m.m21(), m.m31()));
    program_.setUniformValue("row1", QVector3D(m.m12(), m.m22(), m.m32()));
    program_.setUniformValue("size", QVector2D(image.width(), image.height()));
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
  QPainter p(this);
  view_.paint_overlay(p);
  painted_ = true;
}

// --- QPainter -------------------------------------------------------------------------------

RasterSurface::RasterSurface(CanvasView& view) : QWidget(&view), view_(view) {
  as_surface(this);
  setAttribute(Qt::WA_OpaquePaintEvent);  // every pixel of a repaint is drawn below
}

void RasterSurface::image_changed(const QRect&, const QRect& shown) {
  if (!shown.isEmpty()) update(shown);
}

void RasterSurface::paintEvent(QPaintEvent* e) {
  view_.pull();  // the first frame, and a frame that came since the update
  const QImage& image = view_.image();
  QPainter p(this);  // clipped to the region to repaint
  p.fillRect(e->rect(), kBackground);
  if (!image.isNull()) {
    p.setTransform(view_.canvas_transform());
    // Cells stay crisp from 1:1 up; smaller zooms are filtered.
    p.setRenderHint(QPainter::SmoothPixmapTransform, view_.zoom() < 1.f);
    p.drawImage(QPointF(0, 0), image);
    p.resetTransform();
  }
  view_.paint_overlay(p);
  p.end();
  int64_t pixels = 0;
  for (const QRect& r : e->region()) pixels += int64_t(r.width()) * r.height();
  view_.presented(pixels);
}

}  // namespace wb::studio
