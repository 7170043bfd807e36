// The canvas view: shows the renderer's image of the canvas with pan, zoom and rotation, turns
// tablet and mouse input into pen inputs in canvas cells, and measures the pen-to-paint latency.
// What draws the picture is its surface (canvas_surface.h): an OpenGL texture (only the changed
// rectangle is uploaded per frame) or QPainter (only the changed rectangle is repainted), one
// view either way; OpenGL where a context can be made, QPainter where not (docs/STUDIO.md "View").
#pragma once
#include <QImage>
#include <QInputEvent>
#include <QPointF>
#include <QTransform>
#include <QWidget>

#include <functional>
#include <optional>
#include <vector>

#include "studio/frame_cache.h"
#include "studio/latency.h"
#include "studio/pen_clock.h"

class QOpenGLWidget;

namespace wb::studio {

class CanvasSurface;

/// How the canvas is drawn: `Auto` is OpenGL when a context can be made, QPainter otherwise.
enum class ViewKind { Auto, Gl, Raster };

/// "auto", "gl" or "raster"; nothing for another name.
std::optional<ViewKind> parse_view_kind(const QString& name);
const char* view_kind_name(ViewKind k);
/// Whether the OpenGL view can work here, checked once: a platform that composes widgets through
/// OpenGL (not offscreen, minimal, linuxfb or vnc) on which an OpenGL context can be made current
/// on an offscreen surface. QOpenGLWidget crashes where either is missing.
bool opengl_available();

class CanvasView : public QWidget {
  Q_OBJECT
 public:
  /// `kind` Auto is resolved here (opengl_available).
  explicit CanvasView(ViewKind kind = ViewKind::Auto, QWidget* parent = nullptr);
  ~CanvasView() override;

  /// Gl or Raster.
  ViewKind kind() const { return kind_; }
  /// The OpenGL widget that draws the canvas (null for the raster view).
  QOpenGLWidget* gl_widget() const;

  /// Where new pixels come from: fills `canvas` where it changed and says where, with the pen
  /// events that these pixels show first.
  void set_frame_source(std::function<FrameUpdate(QImage&)> source) { source_ = std::move(source); }
  /// The source has a new frame: takes it and redraws what changed.
  void frame_ready();
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
  /// Canvas cells -> widget pixels.
  QTransform canvas_transform() const;

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
  /// Widget pixels repainted so far (the raster view repaints the changed rectangles only; the
  /// OpenGL view draws the whole widget every frame).
  int64_t pixels_drawn() const { return pixels_; }
  /// Pen-to-paint latencies measured by this view.
  LatencyLog& latency() { return latency_; }
  const LatencyLog& latency() const { return latency_; }

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
  void resizeEvent(QResizeEvent* e) override;
  void tabletEvent(QTabletEvent* e) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;

 private:
  friend class GlSurface;
  friend class RasterSurface;

  // --- for the surfaces ---
  /// Takes what the source has (the image's changed rectangle and its pen events) and asks the
  /// surface to draw it.
  void pull();
  const QImage& image() const { return image_; }
  /// Draws the brush footprint under the cursor.
  void paint_overlay(QPainter& p) const;
  /// A frame of `pixels` widget pixels reached the window: the pen events it shows are timed.
  void presented(int64_t pixels);
  /// The pen events taken so far are on screen now.
  void time_inputs();

  PenInput input_at(QPointF widget_pos, float pressure, float tilt_x, float tilt_y, float twist) const;
  /// The cursor moved to `pos` (widget pixels; (-1, -1): gone): redraws its old and new footprint.
  void move_cursor(QPointF pos);
  QRect cursor_rect(QPointF pos) const;

  ViewKind kind_;
  CanvasSurface* surface_ = nullptr;  ///< a child filling the view, transparent to input
  std::function<FrameUpdate(QImage&)> source_;
  QImage image_;
  std::vector<InputTiming> awaiting_;  ///< pen events taken with pixels not presented yet
  LatencyLog latency_;
  int canvas_w_ = 1, canvas_h_ = 1;
  bool place_paint_ = false;

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
  int64_t pixels_ = 0;
};

}  // namespace wb::studio
