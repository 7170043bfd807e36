#include "studio/brush_preview.h"

#include <QPainter>
#include <QPainterPath>
#include <algorithm>
#include <cmath>

#include "studio/panels.h"

namespace wb::studio {

namespace {
/// A bristle with no paint on it: the colour of a hog-bristle hair.
const QColor kHair(214, 196, 160);
/// A bristle vertex this close to the canvas plane touches it, cells.
constexpr float kTouch = 1.f;
}  // namespace

BrushPreview::BrushPreview(QWidget* parent) : QWidget(parent) {
  setMinimumSize(200, 100);
  setToolTip("The brush now: side view against the canvas (left) and from below (right); each bristle in "
             "the colour of its paint, paler as it runs dry; bright dots touch the canvas");
}

void BrushPreview::set_picture(BrushPicture picture) {
  picture_ = std::move(picture);
  touching_ = 0;
  for (const Vec3& v : picture_.vertices)
    if (v.z - picture_.canvas_z < kTouch) ++touching_;
  update();
}

void BrushPreview::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  p.fillRect(rect(), QColor(40, 40, 44));
  const BrushPicture& b = picture_;
  const int V = b.vertices_per_bristle;
  if (b.bristles <= 0 || V <= 0 || b.vertices.size() != size_t(b.bristles) * size_t(V)) return;
  // One scale for both views: the bristles' reach around the ferrule, and the canvas below.
  float reach = 1.f;
  for (const Vec3& v : b.vertices) reach = std::max({reach, std::abs(v.x), std::abs(v.y), -v.z});
  const float half_w = 0.5f * float(width()) - 8.f, h = float(height()) - 16.f;
  const float scale = std::min(half_w / (2.f * reach), h / (reach + 2.f));
  // Side view: x across, z up, the ferrule at the top centre of the left half.
  const QPointF side0(0.25 * width(), 8.0);
  // From below: x across, y down the widget, centred in the right half.
  const QPointF under0(0.75 * width(), 0.5 * height());
  const float ground = -b.canvas_z;  // the canvas's depth below the ferrule, cells (>= 0 above it)
  if (ground * scale < h + 8.f) {
    p.setPen(QPen(QColor(150, 150, 150), 1.0, Qt::DashLine));
    const double gy = side0.y() + ground * scale;
    p.drawLine(QPointF(4, gy), QPointF(0.5 * width() - 4, gy));
  }
  p.setPen(QPen(QColor(90, 90, 96), 1.0));
  p.drawLine(QPointF(0.5 * width(), 4), QPointF(0.5 * width(), height() - 4));
  p.fillRect(QRectF(side0.x() - 0.5 * reach * scale, side0.y() - 6, reach * scale, 6), QColor(170, 170, 180));
  for (int k = 0; k < b.bristles; ++k) {
    QColor c = kHair;
    if (b.fill[size_t(k)] > 0.f) {
      const QColor paint = ryb_to_qcolor({b.ryb[size_t(k)].x, b.ryb[size_t(k)].y, b.ryb[size_t(k)].z});
      const float f = std::clamp(b.fill[size_t(k)], 0.f, 1.f);
      c = QColor::fromRgbF(kHair.redF() + (paint.redF() - kHair.redF()) * f,
                           kHair.greenF() + (paint.greenF() - kHair.greenF()) * f,
                           kHair.blueF() + (paint.blueF() - kHair.blueF()) * f);
    }
    QPainterPath side, under;
    for (int i = 0; i < V; ++i) {
      const Vec3 v = b.vertices[size_t(k) * V + i];
      const QPointF ps(side0.x() + v.x * scale, side0.y() - v.z * scale);
      const QPointF pu(under0.x() + v.x * scale, under0.y() + v.y * scale);
      if (i == 0) {
        side.moveTo(ps);
        under.moveTo(pu);
      } else {
        side.lineTo(ps);
        under.lineTo(pu);
      }
    }
    p.setPen(QPen(c, 1.2));
    p.drawPath(side);
    p.drawPath(under);
  }
  // Where the bristles touch the canvas.
  p.setPen(Qt::NoPen);
  p.setBrush(QColor(255, 255, 255, 200));
  for (const Vec3& v : b.vertices)
    if (v.z - b.canvas_z < kTouch) p.drawEllipse(QPointF(under0.x() + v.x * scale, under0.y() + v.y * scale), 1.5, 1.5);
}

}  // namespace wb::studio
