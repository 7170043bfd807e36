// What draws the canvas view's picture (canvas_view.h): the view's image under the view's
// transform, with the brush footprint over it. Two surfaces, one view: OpenGL (the image as one
// texture, the changed rectangle uploaded per frame, the whole widget drawn) and QPainter (only
// the changed rectangle of the widget repainted, for platforms without OpenGL). A surface fills
// its view and takes no input: the view's input and transform are the same for both.
#pragma once
#include <QOpenGLBuffer>
#include <QOpenGLFunctions>
#include <QOpenGLShaderProgram>
#include <QOpenGLWidget>
#include <QRect>
#include <QWidget>

namespace wb::studio {

class CanvasView;

class CanvasSurface {
 public:
  virtual ~CanvasSurface() = default;
  virtual QWidget* widget() = 0;
  /// The view's image changed in `cells` (canvas cells), which cover `shown` of the widget
  /// (pixels; empty when out of sight): draw them.
  virtual void image_changed(const QRect& cells, const QRect& shown) = 0;
};

/// OpenGL: the image is a texture; a frame uploads what changed and draws the whole widget.
class GlSurface : public QOpenGLWidget, public CanvasSurface, protected QOpenGLFunctions {
 public:
  explicit GlSurface(CanvasView& view);
  ~GlSurface() override;
  QWidget* widget() override { return this; }
  void image_changed(const QRect& cells, const QRect& shown) override;

 protected:
  void initializeGL() override;
  void paintGL() override;

 private:
  CanvasView& view_;
  GLuint texture_ = 0;
  QSize texture_size_;   ///< the texture's size (empty: nothing uploaded yet)
  QRect upload_;         ///< cells changed since the last upload
  bool painting_ = false;
  bool painted_ = false;  ///< painted since the window last swapped (it swaps for every GL child)
  QOpenGLShaderProgram program_;
  QOpenGLBuffer quad_{QOpenGLBuffer::VertexBuffer};
};

/// QPainter: the image drawn into the widget's backing store where it changed, and nowhere else.
class RasterSurface : public QWidget, public CanvasSurface {
 public:
  explicit RasterSurface(CanvasView& view);
  QWidget* widget() override { return this; }
  void image_changed(const QRect& cells, const QRect& shown) override;

 protected:
  void paintEvent(QPaintEvent* e) override;

 private:
  CanvasView& view_;
};

}  // namespace wb::studio
