// `wetbrush replay --video`: the time-lapse decodes back with FFmpeg's libraries as H.264 at the
// asked rate, one frame per speed / fps simulated seconds plus the first and the settled
// painting, and its last frame is the painting the replay renders.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/io/png.h"
#include "media/decoded_video.h"
#include "run_cli.h"

namespace wb::test {
namespace {

/// The CLI's output, its exit status in `code`.
std::string run_cli(const std::string& args, int* code) {
  const RunResult r = wb::test::run_cli(args);
  *code = r.exit_code;
  return r.output;
}

}  // namespace

TEST(Cli, ReplayWritesATimeLapseVideo) {
  const auto dir = std::filesystem::temp_directory_path() / ("wetbrush_video_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string mp4 = (dir / "t.mp4").string(), png = (dir / "p.png").string(), stats = (dir / "s.json").string();
  // The shortest stroke: about 20 frames in all keep the test quick.
  const std::string stroke = std::string(WB_TEST_DATA_DIR) + "/strokes/good/tablet.txt";
  int code = -1;
  const int fps = 10;
  const double speed = 0.25;
  std::string out = run_cli("replay --device cpu --grid-only " + stroke + " --video " + mp4 +
                                " --window 32,32,8 --fps 10 --speed 0.25 -o " + png + " --stats " + stats,
                            &code);
  ASSERT_EQ(code, 0) << out;
  std::printf("%s", out.c_str());
  std::ifstream f(stats);
  const double sim_time = nlohmann::json::parse(f)["sim_time_s"].get<double>();

  const DecodedVideo d = decode_video(mp4);
  const PngPixels p = read_png(png);
  EXPECT_EQ(d.codec, AV_CODEC_ID_H264) << "Debian's libavcodec encodes H.264 with libx264";
  EXPECT_EQ(d.width, p.width + (p.width & 1));
  EXPECT_EQ(d.height, p.height + (p.height & 1));
  // The first frame, one every speed / fps simulated seconds, and the settled painting.
  int expect = 1;
  while (sim_time >= double(expect) * speed / fps - 1e-9) ++expect;
  ++expect;
  std::printf("video: %s %dx%d, %d frames decoded (expected %d for %.3f s simulated), %.3f s at %.1f fps\n",
              avcodec_get_name(d.codec), d.width, d.height, d.frames, expect, sim_time, d.duration_s, d.fps);
  EXPECT_EQ(d.frames, expect);
  EXPECT_NEAR(d.fps, fps, 1e-6);
  EXPECT_NEAR(d.duration_s, double(d.frames) / fps, 1.0 / fps + 1e-6);

  // The last frame is the painting -o wrote, within the codec's loss, over the whole picture and
  // where the paint is (the pixels that differ from the paper's colour in the corner).
  ASSERT_EQ(d.last_rgba.size(), size_t(d.width) * d.height * 4);
  ASSERT_EQ(p.channels, 4);
  double sum = 0, sum_paint = 0;
  int64_t n = 0, n_paint = 0;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const uint8_t* want = &p.data8[(size_t(y) * p.width + x) * 4];
      const uint8_t* got = &d.last_rgba[(size_t(y) * d.width + x) * 4];
      double diff = 0, from_paper = 0;
      for (int c = 0; c < 3; ++c) {
        diff += std::fabs(double(got[c]) - want[c]);
        from_paper += std::fabs(double(want[c]) - p.data8[c]);
      }
      sum += diff, n += 3;
      if (from_paper > 30) sum_paint += diff, n_paint += 3;
    }
  const double mean_abs = sum / double(n), mean_paint = sum_paint / double(std::max<int64_t>(n_paint, 1));
  std::printf("video: last frame against the painting: mean |difference| %.2f of 255, %.2f over %lld painted pixels\n",
              mean_abs, mean_paint, static_cast<long long>(n_paint / 3));
  EXPECT_GT(n_paint / 3, 200) << "the stroke left paint to compare";
  EXPECT_LT(mean_abs, 2.0);
  EXPECT_LT(mean_paint, 6.0);

  // A video that cannot be written fails before the replay, with the path in the message.
  out = run_cli("replay --device cpu --grid-only -q " + stroke + " --video /nonexistent-dir/t.mp4", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("/nonexistent-dir/t.mp4"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

}  // namespace wb::test
