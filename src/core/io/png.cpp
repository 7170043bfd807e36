// PNG encoding and decoding through libpng, in memory; errors become wb::Error.
#include "core/io/png.h"

#include <png.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "core/exec/error.h"
#include "core/io/atomic_file.h"

namespace wb {

namespace {
struct WriteCtx {
  std::vector<uint8_t>* out;
};
void png_write_mem(png_structp png, png_bytep data, png_size_t n) {
  auto* ctx = static_cast<WriteCtx*>(png_get_io_ptr(png));
  ctx->out->insert(ctx->out->end(), data, data + n);
}
void png_flush_mem(png_structp) {}

struct ReadCtx {
  const uint8_t* p;
  size_t size, pos;
};
void png_read_mem(png_structp png, png_bytep data, png_size_t n) {
  auto* ctx = static_cast<ReadCtx*>(png_get_io_ptr(png));
  if (ctx->pos + n > ctx->size) png_error(png, "truncated PNG data");
  std::memcpy(data, ctx->p + ctx->pos, n);
  ctx->pos += n;
}
[[noreturn]] void png_error_fn(png_structp png, png_const_charp msg) {
  auto* err = static_cast<std::string*>(png_get_error_ptr(png));
  if (err) *err = msg;
  png_longjmp(png, 1);
}
void png_warning_fn(png_structp, png_const_charp) {}

// Shared writer: rows of bytes (8-bit) or big-endian 16-bit samples.
// The libpng part: no object with a destructor is created between setjmp and the longjmp.
void encode_into(std::vector<uint8_t>& out, std::vector<png_text>& texts, const std::vector<const uint8_t*>& rows,
                 int width, int height, int color_type, int bit_depth, int level) {
  std::string err;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_error_fn, png_warning_fn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    WB_THROW("PNG: out of memory");
  }
  WriteCtx ctx{&out};
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    WB_THROW("PNG: encoding failed: " + err);
  }
  png_set_write_fn(png, &ctx, png_write_mem, png_flush_mem);
  png_set_compression_level(png, level);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (!texts.empty()) png_set_text(png, info, texts.data(), int(texts.size()));
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) png_write_row(png, const_cast<png_bytep>(rows[size_t(y)]));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
}

std::vector<uint8_t> encode(const std::vector<const uint8_t*>& rows, int width, int height, int color_type,
                            int bit_depth, int level, const std::vector<std::pair<std::string, std::string>>& text) {
  WB_REQUIRE(width > 0 && height > 0, "PNG: image size must be positive");
  std::vector<uint8_t> out;
  std::vector<png_text> texts(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    texts[i].compression = PNG_TEXT_COMPRESSION_NONE;
    texts[i].key = const_cast<char*>(text[i].first.c_str());
    texts[i].text = const_cast<char*>(text[i].second.c_str());
    texts[i].text_length = text[i].second.size();
  }
  encode_into(out, texts, rows, width, height, color_type, bit_depth, level);
  return out;
}
}  // namespace

std::vector<uint8_t> encode_png8(const uint8_t* pixels, int width, int height, int channels, int level) {
  WB_REQUIRE(channels == 3 || channels == 4, "PNG: 8-bit images must have 3 or 4 channels");
  std::vector<const uint8_t*> rows(static_cast<size_t>(std::max(height, 0)));
  for (int y = 0; y < height; ++y) rows[size_t(y)] = pixels + size_t(y) * width * channels;
  return encode(rows, width, height, channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB, 8, level, {});
}

std::vector<uint8_t> encode_png_gray16(const uint16_t* pixels, int width, int height,
                                       const std::vector<std::pair<std::string, std::string>>& text) {
  WB_REQUIRE(width > 0 && height > 0, "PNG: image size must be positive");
  std::vector<uint8_t> be(size_t(width) * height * 2);  // PNG stores 16-bit samples big-endian
  for (size_t i = 0; i < size_t(width) * height; ++i) {
    be[2 * i] = uint8_t(pixels[i] >> 8);
    be[2 * i + 1] = uint8_t(pixels[i] & 0xff);
  }
  std::vector<const uint8_t*> rows(static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) rows[size_t(y)] = be.data() + size_t(y) * width * 2;
  return encode(rows, width, height, PNG_COLOR_TYPE_GRAY, 16, 6, text);
}

PngPixels decode_png(const uint8_t* bytes, size_t size, const std::string& what, uint64_t max_decoded_bytes) {
  if (size < 8 || png_sig_cmp(bytes, 0, 8) != 0) WB_THROW(what + ": not a PNG image");
  std::string err;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, png_error_fn, png_warning_fn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    WB_THROW("PNG: out of memory");
  }
  PngPixels px;
  std::vector<png_bytep> rows;
  std::vector<uint8_t> raw;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    WB_THROW(what + ": damaged PNG: " + err);
  }
  ReadCtx ctx{bytes, size, 0};
  png_set_read_fn(png, &ctx, png_read_mem);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (w == 0 || h == 0 || w > 65536 || h > 65536) png_error(png, "image size out of range");
  const int ct = png_get_color_type(png, info);
  if (ct == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (ct == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  png_read_update_info(png, info);
  // The header declares the size: check what it decodes to before allocating it.
  const uint64_t decoded = uint64_t(png_get_rowbytes(png, info)) * h;
  if (decoded > max_decoded_bytes) {
    err = std::to_string(w) + " x " + std::to_string(h) + " pixels decode to " + std::to_string(decoded >> 20) +
          " MiB, more than the " + std::to_string(max_decoded_bytes >> 20) + " MiB allowed (refused)";
    png_longjmp(png, 1);
  }
  px.width = int(w);
  px.height = int(h);
  px.channels = png_get_channels(png, info);
  px.bit_depth = png_get_bit_depth(png, info);
  const size_t rowbytes = png_get_rowbytes(png, info);
  raw.resize(rowbytes * h);
  rows.resize(h);
  for (png_uint_32 y = 0; y < h; ++y) rows[y] = raw.data() + rowbytes * y;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  if (px.bit_depth == 16) {
    px.data16.resize(raw.size() / 2);
    for (size_t i = 0; i < px.data16.size(); ++i) px.data16[i] = uint16_t((raw[2 * i] << 8) | raw[2 * i + 1]);
  } else {
    px.data8 = std::move(raw);
  }
  return px;
}

std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) WB_THROW(path + ": cannot open for reading");
  std::vector<uint8_t> b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (f.bad()) WB_THROW(path + ": read failed");
  return b;
}

void write_png8(const std::string& path, const uint8_t* pixels, int width, int height, int channels) {
  write_file_atomic(path, encode_png8(pixels, width, height, channels));
}
void write_png_gray16(const std::string& path, const uint16_t* pixels, int width, int height,
                      const std::vector<std::pair<std::string, std::string>>& text) {
  write_file_atomic(path, encode_png_gray16(pixels, width, height, text));
}
PngPixels read_png(const std::string& path) {
  const auto b = read_file(path);
  return decode_png(b.data(), b.size(), path);
}

}  // namespace wb
