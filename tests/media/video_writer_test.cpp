// The time-lapse encoder on its own: H.264 and the MPEG-4 fallback both decode back to the frames
// given, an odd size padded to even, the frame count and rate kept.
#include <gtest/gtest.h>
#include <unistd.h>


#include <cmath>
#include <filesystem>
#include <string>

#include "core/exec/error.h"
#include "media/decoded_video.h"
#include "media/video_writer.h"

namespace wb::test {
namespace {

/// A smooth gradient that moves with the frame number (what an encoder keeps well).
Image gradient(int w, int h, int frame) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = uint8_t(40 + 3 * x + 20 * frame), p[1] = uint8_t(60 + 3 * y), p[2] = 128, p[3] = 255;
    }
  return img;
}

/// Mean absolute difference of a decoded luma plane (`stride` wide) from the gradient's luma.
double mean_abs_luma(const std::vector<uint8_t>& y_plane, int stride, const Image& want) {
  double sum = 0;
  for (int y = 0; y < want.height; ++y)
    for (int x = 0; x < want.width; ++x) {
      const uint8_t* p = want.at(x, y);
      const double luma = 16 + (65.481 * p[0] + 128.553 * p[1] + 24.966 * p[2]) / 255.0;  // BT.601 limited
      sum += std::fabs(y_plane[size_t(y) * stride + x] - luma);
    }
  return sum / (double(want.width) * want.height);
}

}  // namespace

TEST(VideoWriterTest, H264AndTheMpeg4FallbackDecodeBackToTheFrames) {
  const auto dir = std::filesystem::temp_directory_path() / ("wetbrush_video_writer_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const int w = 33, h = 17, n = 6;  // odd: padded to 34 x 18
  for (const auto& [encoder, id] : {std::pair{std::string(), AV_CODEC_ID_H264}, std::pair{std::string("mpeg4"), AV_CODEC_ID_MPEG4}}) {
    const std::string path = (dir / ("v-" + (encoder.empty() ? std::string("default") : encoder) + ".mp4")).string();
    VideoWriter v(path, w, h, 12, encoder);
    EXPECT_EQ(v.fallback_note().empty(), true);
    for (int k = 0; k < n; ++k) v.add_frame(gradient(w, h, k));
    EXPECT_THROW(v.add_frame(gradient(w + 1, h, 0)), Error);  // a frame of another size
    v.finish();
    const DecodedVideo d = decode_video(path);
    EXPECT_EQ(d.codec, id) << encoder;
    EXPECT_EQ(d.width, 34);
    EXPECT_EQ(d.height, 18);
    EXPECT_EQ(d.frames, n) << encoder;
    EXPECT_NEAR(d.fps, 12.0, 1e-9);
    ASSERT_EQ(d.last_y.size(), size_t(d.width) * d.height) << encoder;
    EXPECT_LT(mean_abs_luma(d.last_y, d.width, gradient(w, h, n - 1)), 3.0)
        << encoder << ": the last frame decodes to the last frame given";
  }
  // No frames, or an encoder libavcodec lacks: errors, and no file.
  const std::string empty = (dir / "empty.mp4").string();
  VideoWriter none(empty, w, h, 12);
  EXPECT_THROW(none.finish(), Error);
  EXPECT_FALSE(std::filesystem::exists(empty));
  EXPECT_THROW(VideoWriter((dir / "x.mp4").string(), w, h, 12, "no-such-encoder"), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace wb::test
