// PNG files and buffers (libpng): 8-bit RGB/RGBA and 16-bit grey, for renders, exports and
// the layers of painting files. Reading is for tests and for loading painting thumbnails.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/io/limits.h"

namespace wb {

/// Raw pixels as decoded: `channels` interleaved samples per pixel, 8 or 16 bits each
/// (16-bit samples in host order in `data16`).
struct PngPixels {
  int width = 0, height = 0, channels = 0, bit_depth = 8;
  std::vector<uint8_t> data8;
  std::vector<uint16_t> data16;
};

/// Encodes 8-bit pixels (channels 3 = RGB or 4 = RGBA, rows top to bottom) as a PNG in memory.
std::vector<uint8_t> encode_png8(const uint8_t* pixels, int width, int height, int channels,
                                 int compression_level = 6);
/// Encodes 16-bit grey pixels as a PNG in memory; `text` pairs become tEXt chunks.
std::vector<uint8_t> encode_png_gray16(const uint16_t* pixels, int width, int height,
                                       const std::vector<std::pair<std::string, std::string>>& text = {});
/// Decodes a PNG held in memory (any colour type; palette and grey < 8 bits expanded to 8 bits).
/// `what` names the source in error messages. An image that would decode to more than
/// `max_decoded_bytes` is refused from its header, before the pixels are allocated.
PngPixels decode_png(const uint8_t* bytes, size_t size, const std::string& what,
                     uint64_t max_decoded_bytes = kMaxPngDecodedBytes);

void write_png8(const std::string& path, const uint8_t* pixels, int width, int height, int channels);
void write_png_gray16(const std::string& path, const uint16_t* pixels, int width, int height,
                      const std::vector<std::pair<std::string, std::string>>& text = {});
PngPixels read_png(const std::string& path);

/// Reads a whole file; throws wb::Error naming the path on failure.
std::vector<uint8_t> read_file(const std::string& path);

}  // namespace wb
