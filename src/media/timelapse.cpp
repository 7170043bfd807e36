#include "media/timelapse.h"

#include <cmath>

#include "core/exec/error.h"

namespace wb {

TimelapseRecorder::TimelapseRecorder(const std::string& path, const CanvasRect& region, int canvas_depth,
                                     const TimelapseOptions& options)
    : options_(options) {
  WB_REQUIRE(options.fps >= 1 && options.fps <= 240, "time-lapse: frames per second must be in 1..240");
  WB_REQUIRE(std::isfinite(options.speed) && options.speed > 0.0 && options.speed <= 1e6,
             "time-lapse: the speed must be > 0 simulated seconds per second");
  camera_ = Camera::top_region(float(region.x0), float(region.y0), float(region.width), float(region.height), 1.f);
  if (options.oblique) {
    // The whole-canvas oblique camera of a canvas the region's size, moved onto the region.
    camera_ = Camera::oblique(CanvasDims{region.width, region.height, canvas_depth});
    camera_.center_x += float(region.x0);
    camera_.center_y += float(region.y0);
  }
  video_ = std::make_unique<VideoWriter>(path, camera_.width, camera_.height, options.fps);
}

TimelapseRecorder::~TimelapseRecorder() = default;

void TimelapseRecorder::begin(Session& session) { video_->add_frame(session.render(camera_)); }

void TimelapseRecorder::after_step(Session& session, double sim_time) {
  // Multiples of the interval, not a running sum, so a replay of T simulated seconds gives
  // 2 + floor(T * fps / speed) frames whatever its step size.
  for (; sim_time >= double(next_) * options_.speed / options_.fps - 1e-9; ++next_) video_->add_frame(session.render(camera_));
}

void TimelapseRecorder::finish(Session& session, const Image* painting) {
  video_->add_frame(painting ? *painting : session.render(camera_));
  video_->finish();
}

int64_t write_timelapse(const Stroke& stroke, const SimConfig& config, const std::string& path,
                        const TimelapseOptions& options, const std::function<bool(int64_t done, int64_t total)>& progress) {
  Session session(config, start_pose(stroke));
  session.begin_replay(stroke);
  const Replay& replay = *session.replay();
  TimelapseRecorder rec(path, replay.region(), stroke.canvas.depth, options);
  rec.begin(session);
  while (session.advance()) {
    rec.after_step(session, replay.sim_time());
    if (progress && !progress(replay.steps_done(), replay.step_count())) WB_THROW(path + ": time-lapse cancelled");
  }
  session.settle();
  rec.finish(session);
  return rec.video().frames();
}

}  // namespace wb
