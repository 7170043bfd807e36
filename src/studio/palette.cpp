#include "studio/palette.h"

#include <QVBoxLayout>

#include <algorithm>
#include <cmath>


namespace wb::studio {

void put_paint_dab(TileStore& canvas, float cx, float cy, float radius, float height, const PaintLoad& paint) {
  const CanvasDims d = canvas.dims();
  const int x0 = std::max(0, int(std::floor(cx - radius))), x1 = std::min(d.width - 1, int(std::ceil(cx + radius)));
  const int y0 = std::max(0, int(std::floor(cy - radius))), y1 = std::min(d.height - 1, int(std::ceil(cy + radius)));
  if (x0 > x1 || y0 > y1) return;
  for (int ty = y0 / kTileSize; ty <= y1 / kTileSize; ++ty)
    for (int tx = x0 / kTileSize; tx <= x1 / kTileSize; ++tx) {
      TileData t = canvas.read_tile(ty * canvas.tiles_x() + tx);
      bool touched = false;
      for (int ly = 0; ly < kTileSize; ++ly)
        for (int lx = 0; lx < kTileSize; ++lx) {
          const int x = tx * kTileSize + lx, y = ty * kTileSize + ly;
          const float r2 = ((x + 0.5f - cx) * (x + 0.5f - cx) + (y + 0.5f - cy) * (y + 0.5f - cy)) / (radius * radius);
          if (x >= d.width || y >= d.height || r2 >= 1.f) continue;
          // The dome's column on top of the paint already there (whole cells of it).
          float h = height * (1.f - r2);
          auto at = [&](int z) { return (size_t(z) * kTileSize + ly) * kTileSize + lx; };
          int z = 0;
          while (z < d.depth && t.density[at(z)] >= 1.f) ++z;
          for (; z < d.depth && h > 0.f; ++z) {
            const size_t i = at(z);
            const float old = t.density[i], add = std::min(h, 1.f - old);
            if (add <= 0.f) continue;
            const float m = old + add;
            auto mix = [&](uint16_t& q, float v) { q = encode_unorm16((decode_unorm16(q) * old + v * add) / m); };
            mix(t.pigment_r[i], paint.ryb[0]);
            mix(t.pigment_y[i], paint.ryb[1]);
            mix(t.pigment_b[i], paint.ryb[2]);
            mix(t.oil[i], paint.oil);
            t.dryness[i] = encode_unorm16(decode_unorm16(t.dryness[i]) * old / m);  // fresh paint is wet
            t.density[i] = m;
            h -= add;
            touched = true;
          }
        }
      if (touched) canvas.write_tile(t);
    }
}

PalettePanel::PalettePanel(const SimConfig& config, const RenderParams& render, int width, int height, ViewKind view,
                           QWidget* parent)
    : QWidget(parent), clock_(width, height) {
  SimConfig c = config;
  c.canvas.width = width;
  c.canvas.height = height;
  c.window = Int3{std::min(c.window.x, width), std::min(c.window.y, height), c.window.z};
  RenderParams rp = render;
  rp.paper_rgb = Vec3(0.86f, 0.85f, 0.82f);  // a pale grey glass palette
  sim_ = std::make_unique<SimThread>(c, rp);
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
  connect(&hold_timer_, &QTimer::timeout, this, [this] {
    if (clock_.down()) push(clock_.hold(wall_now()));
  });
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
    // About a fifth of the palette's height across, a third as high as wide (a squeezed-out
    // dab of stiff paint), within half the paint depth.
    const CanvasDims d = s.sim().canvas().dims();
    const float radius = std::max(4.f, 0.1f * float(std::min(d.width, d.height)));
    const float height = std::min(0.6f * radius, 0.5f * float(d.depth));
    s.write_canvas([&](TileStore& canvas) { put_paint_dab(canvas, cx, cy, radius, height, paint); });
    s.invalidate_rect(int(cx - radius) - 1, int(cy - radius) - 1, int(cx + radius) + 2, int(cy + radius) + 2);
  });
}

}  // namespace wb::studio
