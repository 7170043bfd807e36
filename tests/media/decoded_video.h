// A video file decoded back with FFmpeg's libraries, independently of the writer
// (media/video_writer.h): the stream's codec, size, rate and duration, the frame count and the
// last frame, its luma plane as decoded and its RGBA by BT.601's limited-range formulas.
#pragma once
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace wb::test {

struct DecodedVideo {
  AVCodecID codec = AV_CODEC_ID_NONE;
  int width = 0, height = 0, frames = 0;
  double duration_s = 0, fps = 0;
  std::vector<uint8_t> last_y;     ///< the last frame's luma, width x height
  std::vector<uint8_t> last_rgba;  ///< the last frame, RGBA (YUV 4:2:0 frames only)
};

inline DecodedVideo decode_video(const std::string& path) {
  DecodedVideo d;
  AVFormatContext* fmt = nullptr;
  if (avformat_open_input(&fmt, path.c_str(), nullptr, nullptr) < 0) return d;
  avformat_find_stream_info(fmt, nullptr);
  const int si = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (si < 0) return avformat_close_input(&fmt), d;
  const AVStream* st = fmt->streams[si];
  d.codec = st->codecpar->codec_id;
  d.width = st->codecpar->width;
  d.height = st->codecpar->height;
  d.duration_s = st->duration * av_q2d(st->time_base);
  d.fps = av_q2d(st->avg_frame_rate);
  const AVCodec* codec = avcodec_find_decoder(d.codec);
  AVCodecContext* ctx = avcodec_alloc_context3(codec);
  avcodec_parameters_to_context(ctx, st->codecpar);
  avcodec_open2(ctx, codec, nullptr);
  AVPacket* pkt = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  auto drain = [&] {
    while (avcodec_receive_frame(ctx, frame) == 0) {
      ++d.frames;
      const int w = frame->width, h = frame->height;
      d.last_y.resize(size_t(w) * h);
      for (int y = 0; y < h; ++y)
        std::copy_n(frame->data[0] + y * frame->linesize[0], w, d.last_y.begin() + ptrdiff_t(y) * w);
      d.last_rgba.assign(size_t(w) * h * 4, 255);
      if (frame->format != AV_PIX_FMT_YUV420P) continue;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const double Y = 1.164 * (frame->data[0][y * frame->linesize[0] + x] - 16.0);
          const double U = frame->data[1][(y / 2) * frame->linesize[1] + x / 2] - 128.0;
          const double V = frame->data[2][(y / 2) * frame->linesize[2] + x / 2] - 128.0;
          const double rgb[3] = {Y + 1.596 * V, Y - 0.813 * V - 0.391 * U, Y + 2.018 * U};
          for (int c = 0; c < 3; ++c)
            d.last_rgba[(size_t(y) * w + x) * 4 + c] = uint8_t(std::lround(std::clamp(rgb[c], 0.0, 255.0)));
        }
    }
  };
  while (av_read_frame(fmt, pkt) >= 0) {
    if (pkt->stream_index == si) {
      avcodec_send_packet(ctx, pkt);
      drain();
    }
    av_packet_unref(pkt);
  }
  avcodec_send_packet(ctx, nullptr);
  drain();
  av_frame_free(&frame);
  av_packet_free(&pkt);
  avcodec_free_context(&ctx);
  avformat_close_input(&fmt);
  return d;
}

}  // namespace wb::test
