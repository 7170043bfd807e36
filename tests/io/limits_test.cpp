// Resource limits on untrusted files (docs/RELIABILITY.md "Resource limits"): each hostile file
// is crafted here, small, and must be refused with a clear message in bounded time and without
// allocating what it declares (peak resident memory grows by less than 64 MiB).
#include <sys/resource.h>
#include <zlib.h>
#include <zstd.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "backend_fixture.h"
#include "core/io/document.h"
#include "core/io/limits.h"
#include "core/io/png.h"
#include "core/io/stroke.h"
#include "io/test_zip.h"

namespace wb::test {

namespace {

void put_u32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_u64(std::vector<uint8_t>& b, uint64_t v) {
  for (int i = 0; i < 8; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_be32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 3; i >= 0; --i) b.push_back(uint8_t(v >> (8 * i)));
}
uint32_t crc_of(const uint8_t* p, size_t n) { return uint32_t(crc32(crc32(0L, Z_NULL, 0), p, uInt(n))); }

/// A volume entry (docs/FORMATS.md) declaring a w x h x d canvas whose tiles (0..count-1 along
/// the rows) all hold the same compressed data, each tile stored back to back.
std::vector<uint8_t> volume_with_tiles(uint32_t w, uint32_t h, uint32_t d, uint32_t count,
                                       const std::vector<uint8_t>& tile_data) {
  std::vector<uint8_t> v = {'W', 'B', 'V', 'O', 'L', 'U', 'M', 'E'};
  for (uint32_t x : {1u, 0u, w, h, d, 16u, 6u, count}) put_u32(v, x);
  const uint32_t tiles_x = (w + 15) / 16;
  for (uint32_t k = 0; k < count; ++k) {
    put_u32(v, k % tiles_x);
    put_u32(v, k / tiles_x);
    put_u64(v, uint64_t(k) * tile_data.size());
    put_u64(v, tile_data.size());
    put_u32(v, crc_of(tile_data.data(), tile_data.size()));
  }
  put_u32(v, crc_of(v.data(), v.size()));
  for (uint32_t k = 0; k < count; ++k) v.insert(v.end(), tile_data.begin(), tile_data.end());
  return v;
}

std::vector<uint8_t> painting_with_volume(const std::vector<uint8_t>& volume, bool deflate = false) {
  return make_zip({{"mimetype", bytes_of("image/openraster")}, {"wetbrush/volume.bin", volume}}, deflate);
}

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

/// Runs `read`, which must throw wb::Error containing `message`, within `seconds` and without
/// raising the process's peak resident memory by 64 MiB or more.
void expect_refused(const std::function<void()>& read, const std::string& message, double seconds = 2.0) {
  const long rss0 = peak_rss_kib();
  const auto t0 = std::chrono::steady_clock::now();
  try {
    read();
    ADD_FAILURE() << "accepted; expected a refusal with '" << message << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, seconds) << "refusal took " << s << " s";
  EXPECT_LT(peak_rss_kib() - rss0, 64 * 1024) << "peak resident memory grew by " << (peak_rss_kib() - rss0) << " KiB";
}

}  // namespace

class LimitsTest : public BackendTest {};

// A stroke file or a painting declaring a canvas beyond kMaxCanvasCells (the whole-canvas
// picture of a replay or a save would need 16 GiB for 65536 x 65536).
TEST_F(LimitsTest, HugeDeclaredCanvasIsRefused) {
  const std::string stroke = R"({"format": "wetbrush-stroke", "version": 1,
    "canvas": {"width": 65536, "height": 65536},
    "samples": [{"t": 0, "x": 10, "y": 10, "pressure": 0.5}]})";
  expect_refused([&] { parse_stroke_text(stroke, "huge.json"); }, "more than 268435456 cells");
  // The largest allowed area still reads (65536 x 4096 cells).
  const std::string wide = R"({"format": "wetbrush-stroke", "version": 1,
    "canvas": {"width": 65536, "height": 4096},
    "samples": [{"t": 0, "x": 10, "y": 10, "pressure": 0.5}]})";
  EXPECT_EQ(parse_stroke_text(wide, "wide.json").canvas.width, 65536);

  const auto ora = painting_with_volume(volume_with_tiles(65536, 65536, 64, 0, {}));
  expect_refused([&] { load_painting_bytes(ora.data(), ora.size(), "huge.ora", device_); },
                 "65536 x 65536 has more than 268435456 cells");
  const auto ok = painting_with_volume(volume_with_tiles(65536, 4096, 64, 0, {}));
  EXPECT_EQ(load_painting_bytes(ok.data(), ok.size(), "wide.ora", device_).canvas.dims().height, 4096);
}

// A ZIP entry whose declared uncompressed size is beyond the limit is refused from the
// archive's directory, before anything is allocated or inflated: here 64 MiB of zeros deflated
// to about 64 KiB against a 1 MiB limit (the default limit is 1 GiB).
TEST_F(LimitsTest, ZipEntryDecompressingBeyondTheLimitIsRefused) {
  const std::vector<uint8_t> zeros(size_t(64) << 20, 0);
  const auto ora = painting_with_volume(zeros, /*deflate=*/true);
  ASSERT_LT(ora.size(), size_t(1) << 20);
  LoadLimits limits;
  limits.max_volume_entry_bytes = uint64_t(1) << 20;
  expect_refused([&] { load_painting_bytes(ora.data(), ora.size(), "bomb.ora", device_, limits); },
                 "declares 67108864 bytes uncompressed, more than the 1048576 bytes allowed");
  EXPECT_EQ(LoadLimits{}.max_volume_entry_bytes, uint64_t(1) << 30);

  // The metadata entry has its own limit (16 MiB by default).
  const auto meta = make_zip({{"mimetype", bytes_of("image/openraster")},
                              {"wetbrush/volume.bin", volume_with_tiles(16, 16, 4, 0, {})},
                              {"wetbrush/metadata.json", std::vector<uint8_t>(size_t(32) << 20, ' ')}},
                             true);
  expect_refused([&] { load_painting_bytes(meta.data(), meta.size(), "meta.ora", device_); },
                 "'wetbrush/metadata.json' declares 33554432 bytes");
}

// A PNG whose header claims 65536 x 65536 RGBA (16 GiB decoded) is refused from its header.
TEST_F(LimitsTest, PngClaimingHugeSizeIsRefused) {
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<uint8_t> ihdr = {'I', 'H', 'D', 'R'};
  put_be32(ihdr, 65536);
  put_be32(ihdr, 65536);
  for (uint8_t b : {8, 6, 0, 0, 0}) ihdr.push_back(b);  // 8-bit RGBA, deflate, no filter, no interlace
  put_be32(png, 13);
  png.insert(png.end(), ihdr.begin(), ihdr.end());
  put_be32(png, crc_of(ihdr.data(), ihdr.size()));
  // One IDAT chunk of a zlib stream of a few zero rows.
  std::vector<uint8_t> row(65536 * 4 + 1, 0), z(compressBound(uLong(row.size())));
  uLongf zn = uLongf(z.size());
  ASSERT_EQ(compress2(z.data(), &zn, row.data(), uLong(row.size()), 9), Z_OK);
  std::vector<uint8_t> idat = {'I', 'D', 'A', 'T'};
  idat.insert(idat.end(), z.begin(), z.begin() + long(zn));
  put_be32(png, uint32_t(zn));
  png.insert(png.end(), idat.begin(), idat.end());
  put_be32(png, crc_of(idat.data(), idat.size()));
  expect_refused([&] { decode_png(png.data(), png.size(), "huge.png"); },
                 "65536 x 65536 pixels decode to 16384 MiB, more than the 1024 MiB allowed");
  EXPECT_EQ(kMaxPngDecodedBytes, uint64_t(1) << 30);
}

// The painting of the issue: many tiny zstd frames, each expanding to a whole column of a
// 1024-deep canvas (3.5 MiB). The table declares the paint, so the file is refused before any
// tile is allocated or decompressed: here 2000 tiles (7 GiB) against the 4 GiB default.
TEST_F(LimitsTest, ManyTinyTilesExpandingToGigabytesAreRefused) {
  const size_t raw = size_t(16) * 16 * 1024 * 14;
  const std::vector<uint8_t> zeros(raw, 0);
  std::vector<uint8_t> frame(ZSTD_compressBound(raw));
  frame.resize(ZSTD_compress(frame.data(), frame.size(), zeros.data(), zeros.size(), 19));
  ASSERT_LT(frame.size(), 1024u);
  const auto ora = painting_with_volume(volume_with_tiles(4096, 4096, 1024, 2000, frame));
  ASSERT_LT(ora.size(), size_t(1) << 20);
  expect_refused([&] { load_painting_bytes(ora.data(), ora.size(), "tiles.ora", device_); },
                 "2000 tiles of a 1024-cell-deep canvas hold 7000 MiB of paint, more than the 4096 MiB");
  // Under a smaller limit the same rule holds (the fuzz harness reads with 256 MiB).
  LoadLimits small;
  small.max_paint_bytes = uint64_t(256) << 20;
  const auto few = painting_with_volume(volume_with_tiles(4096, 4096, 1024, 80, frame));
  expect_refused([&] { load_painting_bytes(few.data(), few.size(), "few.ora", device_, small); },
                 "80 tiles of a 1024-cell-deep canvas hold 280 MiB of paint");
  // Within the limit, the same tiles load.
  const auto ok = painting_with_volume(volume_with_tiles(4096, 4096, 1024, 4, frame));
  EXPECT_EQ(load_painting_bytes(ok.data(), ok.size(), "ok.ora", device_, small).canvas.allocated_tiles(), 4);
}

// Tiles must be stored back to back: a table pointing many tiles at the same bytes is refused.
TEST_F(LimitsTest, TilesSharingBytesAreRefused) {
  const size_t raw = size_t(16) * 16 * 4 * 14;
  const std::vector<uint8_t> zeros(raw, 0);
  std::vector<uint8_t> frame(ZSTD_compressBound(raw));
  frame.resize(ZSTD_compress(frame.data(), frame.size(), zeros.data(), zeros.size(), 3));
  std::vector<uint8_t> v = volume_with_tiles(64, 64, 4, 2, frame);
  // Point the second tile at the first tile's bytes, fix the header checksum.
  const size_t e1 = 40 + 28;
  for (int i = 0; i < 8; ++i) v[e1 + 8 + size_t(i)] = 0;
  const size_t header = 40 + 2 * 28;
  const uint32_t c = crc_of(v.data(), header);
  for (int i = 0; i < 4; ++i) v[header + size_t(i)] = uint8_t(c >> (8 * i));
  const auto ora = painting_with_volume(v);
  expect_refused([&] { load_painting_bytes(ora.data(), ora.size(), "shared.ora", device_); },
                 "data overlaps another tile or leaves a gap");
}

}  // namespace wb::test
