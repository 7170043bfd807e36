// The time-lapse encoder on its own: H.264 and the MPEG-4 fallback both decode back to the frames
// given, an odd size padded to even, the frame count and rate kept.
#include <gtest/gtest.h>
#include <unistd.h>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include <cmath>
#include <filesystem>
#include <string>

#include "core/exec/error.h"
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

struct Decoded {
  AVCodecID codec = AV_CODEC_ID_NONE;
  int width = 0, height = 0, frames = 0;
  double fps = 0;
  double last_mean_abs_y = -1;  ///< the last frame's luma against the expected gradient's
};

Decoded decode(const std::string& path, int w, int h, int last_frame) {
  Decoded d;
  AVFormatContext* fmt = nullptr;
  if (avformat_open_input(&fmt, path.c_str(), nullptr, nullptr) < 0) return d;
  avformat_find_stream_info(fmt, nullptr);
  const AVStream* st = fmt->streams[0];
  d.codec = st->codecpar->codec_id, d.width = st->codecpar->width, d.height = st->codecpar->height;
  d.fps = av_q2d(st->avg_frame_rate);
  const AVCodec* codec = avcodec_find_decoder(d.codec);
  AVCodecContext* ctx = avcodec_alloc_context3(codec);
  avcodec_parameters_to_context(ctx, st->codecpar);
  avcodec_open2(ctx, codec, nullptr);
  AVPacket* pkt = av_packet_alloc();
  AVFrame* f = av_frame_alloc();
  const Image want = gradient(w, h, last_frame);
  auto drain = [&] {
    while (avcodec_receive_frame(ctx, f) == 0) {
      ++d.frames;
      double sum = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const uint8_t* p = want.at(x, y);
          const double luma = 16 + (65.481 * p[0] + 128.553 * p[1] + 24.966 * p[2]) / 255.0;  // BT.601 limited
          sum += std::fabs(f->data[0][y * f->linesize[0] + x] - luma);
        }
      d.last_mean_abs_y = sum / (double(w) * h);
    }
  };
  while (av_read_frame(fmt, pkt) >= 0) {
    avcodec_send_packet(ctx, pkt);
    drain();
    av_packet_unref(pkt);
  }
  avcodec_send_packet(ctx, nullptr);
  drain();
  av_frame_free(&f);
  av_packet_free(&pkt);
  avcodec_free_context(&ctx);
  avformat_close_input(&fmt);
  return d;
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
    const Decoded d = decode(path, w, h, n - 1);
    EXPECT_EQ(d.codec, id) << encoder;
    EXPECT_EQ(d.width, 34);
    EXPECT_EQ(d.height, 18);
    EXPECT_EQ(d.frames, n) << encoder;
    EXPECT_NEAR(d.fps, 12.0, 1e-9);
    EXPECT_GE(d.last_mean_abs_y, 0.0);
    EXPECT_LT(d.last_mean_abs_y, 3.0) << encoder << ": the last frame decodes to the last frame given";
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
