#include "media/video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <cstdio>
#include <cstring>
#include <vector>

#include "core/exec/error.h"
#include "core/io/atomic_file.h"

namespace wb {
namespace {

std::string av_error(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

/// The MP4 in memory: the muxer seeks back to finish the header, so the buffer is seekable.
struct MemoryFile {
  std::vector<uint8_t> bytes;
  size_t pos = 0;
  static int write(void* opaque, uint8_t* buf, int size) {
    auto* f = static_cast<MemoryFile*>(opaque);
    if (f->pos + size_t(size) > f->bytes.size()) f->bytes.resize(f->pos + size_t(size));
    std::memcpy(f->bytes.data() + f->pos, buf, size_t(size));
    f->pos += size_t(size);
    return size;
  }
  static int64_t seek(void* opaque, int64_t offset, int whence) {
    auto* f = static_cast<MemoryFile*>(opaque);
    int64_t base = 0;
    switch (whence & ~AVSEEK_FORCE) {
      case AVSEEK_SIZE: return int64_t(f->bytes.size());
      case SEEK_SET: base = 0; break;
      case SEEK_CUR: base = int64_t(f->pos); break;
      case SEEK_END: base = int64_t(f->bytes.size()); break;
      default: return -1;
    }
    if (base + offset < 0) return -1;
    f->pos = size_t(base + offset);
    return int64_t(f->pos);
  }
};

}  // namespace

struct VideoWriter::Impl {
  std::string path, encoder, note;
  int width = 0, height = 0, enc_w = 0, enc_h = 0, fps = 30;
  int64_t frames = 0;
  bool finished = false;
  MemoryFile file;
  AVFormatContext* fmt = nullptr;
  AVIOContext* io = nullptr;
  AVCodecContext* ctx = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;
  std::vector<uint8_t> padded;  ///< the RGBA frame at the encoded (even) size

  ~Impl() {
    sws_freeContext(sws);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&ctx);
    if (fmt) avformat_free_context(fmt);
    if (io) {
      av_freep(&io->buffer);
      avio_context_free(&io);
    }
  }

  void check(int rc, const char* what) const {
    if (rc < 0) WB_THROW(path + ": video: " + what + ": " + av_error(rc));
  }

  /// Sends `f` (nullptr: flush) and writes every packet the encoder gives back.
  void encode(AVFrame* f) {
    check(avcodec_send_frame(ctx, f), "encoding a frame");
    for (;;) {
      const int rc = avcodec_receive_packet(ctx, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
      check(rc, "encoding a frame");
      av_packet_rescale_ts(packet, ctx->time_base, stream->time_base);
      packet->stream_index = stream->index;
      check(av_interleaved_write_frame(fmt, packet), "writing a packet");
    }
  }
};

VideoWriter::VideoWriter(const std::string& path, int width, int height, int fps, const std::string& encoder)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  WB_REQUIRE(width > 0 && height > 0 && width <= 8192 && height <= 8192,
             path + ": video: frame size must be 1..8192 pixels a side");
  WB_REQUIRE(fps >= 1 && fps <= 240, path + ": video: frames per second must be in 1..240");
  m.width = width, m.height = height, m.fps = fps;
  m.enc_w = width + (width & 1), m.enc_h = height + (height & 1);
  // The file is written at finish(); a folder that cannot take it is refused now, before the
  // frames are made.
  std::string folder = std::filesystem::path(path).parent_path().string();
  if (folder.empty()) folder = ".";
  if (::access(folder.c_str(), W_OK) != 0)
    WB_THROW(path + ": cannot write a video in '" + folder + "': " + std::strerror(errno));

  // libx264 reports its statistics on standard error at the default level; errors are enough
  // (they come back as return codes, which the messages below carry).
  av_log_set_level(AV_LOG_ERROR);
  const AVCodec* codec = encoder.empty() ? avcodec_find_encoder(AV_CODEC_ID_H264) : avcodec_find_encoder_by_name(encoder.c_str());
  WB_REQUIRE(codec || encoder.empty(), path + ": video: libavcodec has no encoder '" + encoder + "'");
  if (!codec) {
    codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
    WB_REQUIRE(codec, path + ": video: this machine's libavcodec has neither an H.264 nor an MPEG-4 encoder");
    m.note = "libavcodec has no H.264 encoder here (Debian's links libx264); encoding MPEG-4 Part 2 instead";
  }
  m.encoder = codec->name;

  m.check(avformat_alloc_output_context2(&m.fmt, nullptr, "mp4", nullptr), "no MP4 muxer");
  m.ctx = avcodec_alloc_context3(codec);
  WB_REQUIRE(m.ctx, path + ": video: out of memory");
  m.ctx->width = m.enc_w;
  m.ctx->height = m.enc_h;
  m.ctx->pix_fmt = AV_PIX_FMT_YUV420P;
  m.ctx->time_base = AVRational{1, fps};
  m.ctx->framerate = AVRational{fps, 1};
  m.ctx->gop_size = 2 * fps;  // a key frame every 2 s: seeking in a player stays quick
  // BT.601 limited range: what swscale converts with by default, stated so players agree.
  m.ctx->colorspace = AVCOL_SPC_SMPTE170M;
  m.ctx->color_range = AVCOL_RANGE_MPEG;
  if (codec->id == AV_CODEC_ID_H264) {
    // Painted texture is fine detail: constant quality 18 is visually lossless for it.
    av_opt_set(m.ctx->priv_data, "crf", "18", 0);
    av_opt_set(m.ctx->priv_data, "preset", "medium", 0);
  } else {
    // Fixed quantiser 3 (of 1..31): fine detail survives, as with H.264's crf 18.
    m.ctx->flags |= AV_CODEC_FLAG_QSCALE;
    m.ctx->global_quality = FF_QP2LAMBDA * 3;
  }
  if (m.fmt->oformat->flags & AVFMT_GLOBALHEADER) m.ctx->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  m.check(avcodec_open2(m.ctx, codec, nullptr), "cannot open the encoder");

  m.stream = avformat_new_stream(m.fmt, nullptr);
  WB_REQUIRE(m.stream, path + ": video: out of memory");
  m.stream->time_base = m.ctx->time_base;
  m.stream->avg_frame_rate = m.ctx->framerate;
  m.check(avcodec_parameters_from_context(m.stream->codecpar, m.ctx), "stream parameters");

  constexpr int kIoBuffer = 1 << 16;
  auto* buf = static_cast<unsigned char*>(av_malloc(kIoBuffer));
  WB_REQUIRE(buf, path + ": video: out of memory");
  m.io = avio_alloc_context(buf, kIoBuffer, 1, &m.file, nullptr, &MemoryFile::write, &MemoryFile::seek);
  if (!m.io) {
    av_free(buf);
    WB_THROW(path + ": video: out of memory");
  }
  m.io->seekable = AVIO_SEEKABLE_NORMAL;
  m.fmt->pb = m.io;
  m.fmt->flags |= AVFMT_FLAG_CUSTOM_IO;
  m.check(avformat_write_header(m.fmt, nullptr), "writing the MP4 header");

  m.frame = av_frame_alloc();
  m.packet = av_packet_alloc();
  WB_REQUIRE(m.frame && m.packet, path + ": video: out of memory");
  m.frame->format = AV_PIX_FMT_YUV420P;
  m.frame->width = m.enc_w;
  m.frame->height = m.enc_h;
  m.check(av_frame_get_buffer(m.frame, 0), "frame buffer");
  m.sws = sws_getContext(m.enc_w, m.enc_h, AV_PIX_FMT_RGBA, m.enc_w, m.enc_h, AV_PIX_FMT_YUV420P, SWS_BICUBIC, nullptr,
                         nullptr, nullptr);
  WB_REQUIRE(m.sws, path + ": video: no RGBA to YUV 4:2:0 conversion");
  m.padded.assign(size_t(m.enc_w) * m.enc_h * 4, 0);
}

VideoWriter::~VideoWriter() = default;

void VideoWriter::add_frame(const Image& img) {
  Impl& m = *impl_;
  WB_REQUIRE(!m.finished, m.path + ": video: a frame after finish()");
  WB_REQUIRE(img.width == m.width && img.height == m.height,
             m.path + ": video: frame of " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                 ", the video is " + std::to_string(m.width) + "x" + std::to_string(m.height));
  for (int y = 0; y < m.enc_h; ++y) {
    const uint8_t* src = img.at(0, std::min(y, m.height - 1));
    uint8_t* dst = &m.padded[size_t(y) * m.enc_w * 4];
    std::memcpy(dst, src, size_t(m.width) * 4);
    if (m.enc_w > m.width) std::memcpy(dst + size_t(m.width) * 4, src + size_t(m.width - 1) * 4, 4);
  }
  m.check(av_frame_make_writable(m.frame), "frame buffer");
  const uint8_t* src[1] = {m.padded.data()};
  const int stride[1] = {m.enc_w * 4};
  sws_scale(m.sws, src, stride, 0, m.enc_h, m.frame->data, m.frame->linesize);
  m.frame->pts = m.frames++;
  m.encode(m.frame);
}

void VideoWriter::finish() {
  Impl& m = *impl_;
  WB_REQUIRE(!m.finished, m.path + ": video: finished twice");
  WB_REQUIRE(m.frames > 0, m.path + ": video: no frames to write");
  m.finished = true;
  m.encode(nullptr);
  m.check(av_write_trailer(m.fmt), "finishing the MP4");
  avio_flush(m.io);
  write_file_atomic(m.path, m.file.bytes);
}

const std::string& VideoWriter::encoder() const { return impl_->encoder; }
const std::string& VideoWriter::fallback_note() const { return impl_->note; }
int64_t VideoWriter::frames() const { return impl_->frames; }
int VideoWriter::encoded_width() const { return impl_->enc_w; }
int VideoWriter::encoded_height() const { return impl_->enc_h; }

}  // namespace wb
