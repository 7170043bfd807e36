// Time-lapse video (docs/FORMATS.md "Time-lapse video"): RGBA frames encoded with FFmpeg's
// libraries as H.264 in an MP4 (MPEG-4 Part 2 when this machine's libavcodec has no H.264
// encoder). The whole file is muxed in memory and written atomically at finish(), so a failed or
// interrupted encode leaves no partial video behind.
#pragma once
#include <cstdint>
#include <memory>
#include <string>

#include "core/render/renderer.h"

namespace wb {

class VideoWriter {
 public:
  /// Frames of width x height pixels at `fps`; odd sizes are padded to even ones (4:2:0 chroma
  /// needs them) by repeating the last column or row. Throws wb::Error when no encoder opens.
  /// `encoder` names a libavcodec encoder to use instead of the H.264 default (tests of the
  /// MPEG-4 fallback).
  VideoWriter(const std::string& path, int width, int height, int fps, const std::string& encoder = "");
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  /// Encodes one frame (its size must be the constructor's).
  void add_frame(const Image& frame);
  /// Flushes the encoder, finishes the MP4 and writes the file. No frames is an error.
  void finish();

  /// The encoder in use ("libx264", or "mpeg4" as the fallback).
  const std::string& encoder() const;
  /// Empty, or why the encoder is not H.264 (for the user).
  const std::string& fallback_note() const;
  int64_t frames() const;
  int encoded_width() const;
  int encoded_height() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wb
