// The studio's pictures of the simulation, made on the simulation thread and taken by the UI:
// the canvas image, re-rendered incrementally where the paint changed (CanvasImageCache) as often
// as SimThread asks, the changed rectangle handed over to the view, and the brush as it is now
// (Simulator::brush_picture) for the preview and the paint swatch. One job: SimThread runs the
// simulation and asks this for frames.
#pragma once
#include <QImage>
#include <QRect>

#include <memory>
#include <mutex>
#include <vector>

#include "studio/latency.h"

#include "core/session/session.h"

namespace wb::studio {

/// What the view takes from the simulation for its next frame.
struct FrameUpdate {
  QRect dirty;                      ///< pixels changed since the last take (empty: none)
  std::vector<InputTiming> input_times;  ///< pen events first consumed by these pixels' steps
};

class FrameCache {
 public:
  // --- simulation thread ---
  /// A new painting (or one of another size): a new image cache with its renderer and a black
  /// front image.
  void reset(Session& session);
  bool ready() const { return cache_ != nullptr; }
  /// The whole canvas must be drawn again (light, paper, a new canvas).
  void invalidate_all();
  /// Cells [x0, x1) x [y0, y1) changed.
  void invalidate_rect(int x0, int y0, int x1, int y1);
  /// The step that ended at `at` consumed the pen event that happened at `wall_t` (wall_now): it
  /// goes to the view with the next front image, which stamps when it was published.
  void input_consumed(double wall_t, double at) { inputs_.push_back(InputTiming{wall_t, at, 0.0}); }
  /// Re-renders what changed and copies it to the front image, unless the last render was less
  /// than `min_interval` seconds ago (0: now); the brush picture and the consumed pen events are
  /// taken with it. True when the front image changed.
  bool render(Session& session, double min_interval);
  /// The whole canvas rendered now (one pixel per cell).
  Image canvas_image(Session& session);

  // --- UI thread (locked) ---
  /// Copies the pixels changed since the last call into `canvas`; returns their rectangle and
  /// the pen events they show for the first time.
  FrameUpdate take(QImage& canvas);
  BrushPicture brush_picture() const;

 private:
  std::unique_ptr<CanvasImageCache> cache_;
  CanvasDims dims_{};
  double last_render_ = 0.0;
  int dirty_x0_ = 1 << 30, dirty_y0_ = 1 << 30, dirty_x1_ = -1, dirty_y1_ = -1;
  std::vector<InputTiming> inputs_;  ///< pen events consumed since the last front image
  mutable std::mutex mu_;  ///< guards what the UI takes: front_, front_dirty_, front_inputs_, picture_
  QImage front_;
  QRect front_dirty_;
  std::vector<InputTiming> front_inputs_;
  BrushPicture picture_;
};

}  // namespace wb::studio
