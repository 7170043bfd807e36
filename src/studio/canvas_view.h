// The canvas view: an OpenGL widget that shows the renderer's image of the canvas as one
// texture (only the changed rectangle is uploaded per frame), with pan, zoom and rotation,
// and turns tablet and mouse input into pen inputs in canvas cells.
#pragma once
#include <QImage>
#include <QInputEvent>
#include <QOpenGLBuffer>
#include <QOpenGLFunctions>
#include <QOpenGLShaderProgram>
#include <QOpenGLWidget>
#include <QPointF>

#include <functional>

#include "studio/pen_clock.h"

namespace wb::studio {

class CanvasView : public QOpenGLWidget, protected QOpenGLFunctions {
  Q_OBJECT
 public:
  explicit CanvasView(QWidget* parent = nullptr);
  ~CanvasView() override;

  /// Where new pixels come from: fills `canvas` and returns the changed rectangle.
  void set_frame_source(std::function<QRect(QImage&)> source) { source_ = std::move(source); }
  void set_canvas_size(int w, int h);
  QSize canvas_size() const { return {canvas_w_, canvas_h_}; }

  // View transform.
  float zoom() const { return zoom_; }
  float rotation_deg() const { return rotation_deg_; }
  QPointF center() const { return center_; }
  void set_view(QPointF center, float zoom, float rotation_deg);
  void fit();
  void zoom_by(float factor, QPointF widget_anchor);
  QPointF to_canvas(QPointF widget) const;
  QPointF to_widget(QPointF canvas) const;

  // Input mapping.
  /// Pressure curve exponent: pressure_out = pressure_in ^ gamma.
  void set_pressure_gamma(float g) { gamma_ = g; }
  /// Pressure used for the mouse.
  void set_mouse_pressure(float p) { mouse_pressure_ = p; }
  float mouse_pressure() const { return mouse_pressure_; }
  /// Ctrl + click puts paint down (placePaint) instead of painting: the palette's.
  void set_place_paint(bool on) { place_paint_ = on; }
  /// Brush footprint radius in cells, for the cursor.
  void set_cursor_radius(float r) { cursor_radius_ = r; }
  /// Frames drawn so far (for frame-rate measurement).
  int64_t frames_drawn() const { return frames_; }

 Q_SIGNALS:
  /// Pen input at time t, when it happened on the wall clock (event_time).
  void penPress(wb::studio::PenInput p, double t);
  void penMove(wb::studio::PenInput p, double t);
  void penRelease(wb::studio::PenInput p, double t);
  /// Alt + click (mouse or pen): the eyedropper at this canvas point, cells.
  void pickColor(QPointF canvas);
  /// Ctrl + click where set_place_paint is on: put paint at this canvas point, cells.
  void placePaint(QPointF canvas);
  /// Right-button drag: the light follows the pointer (widget pixels moved since the press);
  /// `done` on release.
  void lightDrag(QPointF moved, bool done);
  void viewChanged();

 protected:
  void initializeGL() override;
  void paintGL() override;
  void resizeGL(int w, int h) override;
  void tabletEvent(QTabletEvent* e) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;

 private:
  PenInput input_at(QPointF widget_pos, float pressure, float tilt_x, float tilt_y, float twist) const;

  std::function<QRect(QImage&)> source_;
  QImage image_;
  int canvas_w_ = 1, canvas_h_ = 1;
  bool place_paint_ = false;
  bool texture_stale_ = true;
  GLuint texture_ = 0;
  QOpenGLShaderProgram program_;
  QOpenGLBuffer quad_{QOpenGLBuffer::VertexBuffer};

  QPointF center_{0.5, 0.5};
  float zoom_ = 1.f;
  float rotation_deg_ = 0.f;
  bool fitted_ = false;

  float gamma_ = 1.f;
  float mouse_pressure_ = 0.5f;
  float cursor_radius_ = 20.f;
  bool pen_down_ = false;
  bool tablet_down_ = false;
  float last_pressure_ = 0.5f;
  PenInput last_input_{};
  /// The time a pen event happened, on the wall clock (wall_now): the input's own timestamp
  /// (milliseconds from the window system) less the least delay seen in the stroke, so that a
  /// stroke keeps its speed when the UI thread is late to take its events; the arrival time
  /// where events carry none. `press` starts a stroke.
  double event_time(const QInputEvent* e, bool press);
  double stamp_offset_ = 0.0;  ///< wall time less event time, the stroke's least
  quint64 last_stamp_ = 0;     ///< the stroke's last event timestamp (0: none)
  bool light_drag_ = false;
  QPointF light_anchor_;
  bool panning_ = false;
  QPointF pan_anchor_;
  QPointF cursor_{-1, -1};
  int64_t frames_ = 0;
};

}  // namespace wb::studio
