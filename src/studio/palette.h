// The palette: a small canvas of its own, simulated by its own SimThread with the painting's
// brush. The artist puts paint out of the wells onto it (Ctrl + click), mixes colours on it with
// the brush (the same simulator: the paint really mixes) and loads the brush by painting through
// a mixed puddle; the brush carries its paint, sample by sample, between the palette and the
// canvas (MainWindow::carry_brush). Saved with the painting (docs/STUDIO.md "Palette").
#pragma once
#include <QTimer>
#include <QWidget>

#include <memory>
#include <vector>

#include "core/session/session.h"
#include "studio/canvas_view.h"
#include "studio/pen_clock.h"
#include "studio/sim_thread.h"

namespace wb::studio {

class PalettePanel : public QWidget {
  Q_OBJECT
 public:
  /// `config`: the painting's (device, brush, window, depth); the palette's canvas is
  /// `width` x `height` cells of it, drawn by a view of `view` kind (the canvas's).
  PalettePanel(const SimConfig& config, const RenderParams& render, int width, int height, ViewKind view,
               QWidget* parent = nullptr);
  ~PalettePanel() override;

  SimThread* sim() const { return sim_.get(); }
  CanvasView* view() const { return view_; }
  bool pen_down() const { return clock_.down(); }
  /// A palette event (dip, wipe, clean) for the brush while it is on the palette: fires in the
  /// next step, or after the release while the pen is down.
  void send_event(const StrokeEvent& e);
  /// Puts a dab of `paint` at canvas point c (a well squeezed out onto the palette).
  void put_paint(QPointF c, const PaintLoad& paint);
  /// Starts the palette's time line again (the brush arrived: a new recording there).
  void restart_clock() { clock_.restart(); }
  /// The palette's canvas was replaced by one of this size (a painting saved with another preset).
  void set_canvas_size(int width, int height) {
    view_->set_canvas_size(width, height);
    clock_ = PenClock(width, height);
  }

 Q_SIGNALS:
  /// A press on the palette, before its samples reach the simulation (the brush is carried here).
  void aboutToPaint();
  /// Ctrl + click: put paint here (canvas cells of the palette).
  void placePaint(QPointF canvas);
  /// Alt + click: the eyedropper on the palette.
  void pickColor(QPointF canvas);

 private:
  void push(const ClockOutput& out) { sim_->push(out); }
  std::unique_ptr<SimThread> sim_;
  CanvasView* view_ = nullptr;
  PenClock clock_;
  QTimer hold_timer_;
  std::vector<StrokeEvent> pending_events_;
};

}  // namespace wb::studio
