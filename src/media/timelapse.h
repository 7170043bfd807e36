// Time-lapse of a replay (docs/FORMATS.md "Time-lapse video"): which frames a replay shows and
// when, for `wetbrush replay --video` and the studio's File > Export time-lapse. Frame 0 is the
// canvas before the first step, frame k the canvas once the simulated time reaches k * speed /
// fps, and the settled painting is the last.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "media/video_writer.h"
#include "core/render/camera.h"
#include "core/render/renderer.h"
#include "core/session/session.h"

namespace wb {

struct TimelapseOptions {
  int fps = 30;
  double speed = 4.0;    ///< simulated seconds per second of video
  bool oblique = false;  ///< the region from 40 degrees above the horizon instead of from above
};

class TimelapseRecorder {
 public:
  /// Frames of the canvas rectangle `region` (one pixel per cell). Throws wb::Error on bad
  /// options or when the video cannot be opened.
  TimelapseRecorder(const std::string& path, const CanvasRect& region, int canvas_depth, const TimelapseOptions& options);
  ~TimelapseRecorder();

  const Camera& camera() const { return camera_; }
  const VideoWriter& video() const { return *video_; }

  /// Frame 0: the canvas before the first step.
  void begin(Session& session);
  /// The frames due once the replay has reached `sim_time` seconds (the live window and the
  /// particles drawn as the painter sees them).
  void after_step(Session& session, double sim_time);
  /// The settled painting as the last frame, then the file is written. `painting`, when given,
  /// is that frame already rendered with camera().
  void finish(Session& session, const Image* painting = nullptr);

 private:
  TimelapseOptions options_;
  Camera camera_;
  std::unique_ptr<VideoWriter> video_;
  int64_t next_ = 1;  ///< the next frame after frame 0
};

/// Replays `stroke` on a fresh session of `config` and writes its time-lapse to `path`.
/// `progress` (may be empty) gets the steps done and their total after each step and returns
/// false to cancel (a wb::Error then, and no file). Returns the frames written.
int64_t write_timelapse(const Stroke& stroke, const SimConfig& config, const std::string& path, const TimelapseOptions& options,
                        const std::function<bool(int64_t done, int64_t total)>& progress = {});

}  // namespace wb
