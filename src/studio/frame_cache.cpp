#include "studio/frame_cache.h"
#include "studio/pen_clock.h"

#include <algorithm>
#include <chrono>
#include <cstring>

namespace wb::studio {

void FrameCache::reset(Session& session) {
  const CanvasDims dims = session.dims();
  dims_ = dims;
  cache_ = std::make_unique<CanvasImageCache>(session.renderer(), Camera::top(dims), 8);
  std::lock_guard lk(mu_);
  front_ = QImage(dims.width, dims.height, QImage::Format_RGBA8888);
  front_.fill(Qt::black);
  front_dirty_ = QRect();
}

void FrameCache::invalidate_all() {
  if (!cache_) return;
  cache_->mark_all_dirty();
  dirty_x0_ = 0;
  dirty_y0_ = 0;
  dirty_x1_ = dims_.width;
  dirty_y1_ = dims_.height;
}

void FrameCache::invalidate_rect(int x0, int y0, int x1, int y1) {
  if (!cache_) return;
  cache_->mark_dirty(x0, y0, x1, y1);
  dirty_x0_ = std::min(dirty_x0_, x0);
  dirty_y0_ = std::min(dirty_y0_, y0);
  dirty_x1_ = std::max(dirty_x1_, x1);
  dirty_y1_ = std::max(dirty_y1_, y1);
}

bool FrameCache::render(Session& session, double min_interval) {
  if (!cache_) return false;
  const double now = wall_now();
  if (now - last_render_ < min_interval) return false;
  last_render_ = now;
  // The brush as it is now (preview, swatch), with every frame and after palette actions.
  BrushPicture picture = session.sim().brush_picture();
  {
    std::lock_guard lk(mu_);
    picture_ = std::move(picture);
  }
  if (dirty_x1_ < 0) return false;
  const Image& img = session.update_image(*cache_);
  // Copy the changed pixels (the marked rectangle grown by the renderer's reach) to the front.
  const int m = 48;
  const QRect r = QRect(QPoint(dirty_x0_ - m, dirty_y0_ - m), QPoint(dirty_x1_ + m, dirty_y1_ + m))
                      .intersected(QRect(0, 0, img.width, img.height));
  dirty_x0_ = dirty_y0_ = 1 << 30;
  dirty_x1_ = dirty_y1_ = -1;
  if (r.isEmpty()) return false;
  std::lock_guard lk(mu_);
  for (int y = r.top(); y <= r.bottom(); ++y)
    std::memcpy(front_.scanLine(y) + r.left() * 4, img.at(r.left(), y), size_t(r.width()) * 4);
  front_dirty_ |= r;
  const double published = wall_now();
  for (InputTiming& t : inputs_) t.published = published;
  front_inputs_.insert(front_inputs_.end(), inputs_.begin(), inputs_.end());
  inputs_.clear();
  return true;
}

Image FrameCache::canvas_image(Session& session) {
  if (!cache_) return {};
  if (dirty_x1_ >= 0) render(session, 0.0);
  return session.update_image(*cache_);
}

FrameUpdate FrameCache::take(QImage& canvas) {
  std::lock_guard lk(mu_);
  if (front_.isNull() || front_dirty_.isEmpty()) return {};
  QRect r = front_dirty_;
  if (canvas.size() != front_.size() || canvas.format() != front_.format()) {
    canvas = front_.copy();
    r = front_.rect();
  } else {
    const int bpp = 4;
    for (int y = r.top(); y <= r.bottom(); ++y)
      std::memcpy(canvas.scanLine(y) + r.left() * bpp, front_.constScanLine(y) + r.left() * bpp, size_t(r.width()) * bpp);
  }
  front_dirty_ = QRect();
  FrameUpdate u{r, std::move(front_inputs_)};
  front_inputs_.clear();
  return u;
}

BrushPicture FrameCache::brush_picture() const {
  std::lock_guard lk(mu_);
  return picture_;
}

}  // namespace wb::studio
