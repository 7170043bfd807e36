#include "studio/palette.h"

#include <QVBoxLayout>

#include <algorithm>
#include <cmath>


namespace wb::studio {

PalettePanel::PalettePanel(const SimConfig& config, const RenderParams& render, int width, int height, ViewKind view,
                           QWidget* parent)
    : QWidget(parent), clock_(width, height) {
  SimConfig c = config;
  c.canvas.width = width;
  c.canvas.height = height;
  c.window = Int3{std::min(c.window.x, width), std::min(c.window.y, height), c.window.z};
  RenderParams rp = render;
  rp.paper_rgb = Vec3(0.86f, 0.85f, 0.82f);  // a pale grey glass palette
  sim_ = std::make_unique<SimThread>(c, rp, 0);  // the palette keeps no undo
  view_ = new CanvasView(view);
  view_->set_frame_source([s = sim_.get()](QImage& img) { return s->take_frame(img); });
  view_->set_canvas_size(width, height);
  view_->set_cursor_radius(c.brush.width * 0.5f);
  view_->set_place_paint(true);
  view_->setMinimumSize(320, 200);
  view_->setToolTip("Ctrl + click: put out the selected well's paint. Paint here to mix; the brush carries its "
                    "paint between palette and canvas. Alt + click: eyedropper.");
  connect(sim_.get(), &SimThread::frameReady, view_, &CanvasView::frame_ready);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);
  layout->addWidget(view_, 1);

  connect(view_, &CanvasView::penPress, this, [this](PenInput p, double t) {
    Q_EMIT aboutToPaint();
    push(clock_.press(p, t, wall_now()));
  });
  connect(view_, &CanvasView::penMove, this, [this](PenInput p, double t) { push(clock_.move(p, t, wall_now())); });
  connect(view_, &CanvasView::penRelease, this, [this](PenInput p, double t) {
    push(clock_.release(p, t));
    for (const StrokeEvent& e : pending_events_) push(clock_.event(e));
    pending_events_.clear();
  });
  connect(view_, &CanvasView::placePaint, this, &PalettePanel::placePaint);
  connect(view_, &CanvasView::pickColor, this, &PalettePanel::pickColor);
  hold_timer_.setInterval(8);
  connect(&hold_timer_, &QTimer::timeout, this, [this] { push(clock_.tick(wall_now(), sim_->paint_runs_on())); });
  hold_timer_.start();
}

PalettePanel::~PalettePanel() = default;

void PalettePanel::send_event(const StrokeEvent& e) {
  if (clock_.down()) {
    pending_events_.push_back(e);
    return;
  }
  push(clock_.event(e));
}

void PalettePanel::put_paint(QPointF c, const PaintLoad& paint) {
  const float cx = float(c.x()), cy = float(c.y());
  sim_->post([cx, cy, paint](SimThread& s) {
    const auto [radius, height] = palette_dab_size(s.session().config());
    s.session().put_paint(cx, cy, radius, height, paint);
    s.invalidate_rect(int(cx - radius) - 1, int(cy - radius) - 1, int(cx + radius) + 2, int(cy + radius) + 2);
  });
}

}  // namespace wb::studio
