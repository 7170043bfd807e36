// OpenRaster painting files with the wetbrush paint volume (libzip, zstd, zlib's CRC32),
// written atomically. See docs/FORMATS.md "Painting files" for the byte layout.
#include "core/io/document.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zip.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <set>

#include "core/exec/error.h"
#include "core/io/atomic_file.h"
#include "core/io/limits.h"
#include "core/io/png.h"

namespace wb {

namespace {

constexpr char kVolumeMagic[8] = {'W', 'B', 'V', 'O', 'L', 'U', 'M', 'E'};
constexpr size_t kFixedHeader = 8 + 4 * 8;  // magic, version, flags, w, h, d, tile, fields, tiles
constexpr size_t kEntryBytes = 4 + 4 + 8 + 8 + 4;

// --- little-endian byte packing -------------------------------------------------------
void put_u32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_u64(std::vector<uint8_t>& b, uint64_t v) {
  for (int i = 0; i < 8; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
uint32_t get_u32(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }
uint64_t get_u64(const uint8_t* p) { return uint64_t(get_u32(p)) | uint64_t(get_u32(p + 4)) << 32; }
uint32_t crc(const uint8_t* p, size_t n) { return uint32_t(crc32(crc32(0L, Z_NULL, 0), p, uInt(n))); }

// Raw tile payload: density float32 then pigment R, Y, B, oil, dryness as uint16, each n values.
std::vector<uint8_t> pack_tile(const TileData& t) {
  const size_t n = t.density.size();
  std::vector<uint8_t> raw;
  raw.reserve(n * kCellBytes);
  for (float f : t.density) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    put_u32(raw, u);
  }
  for (const auto* v : {&t.pigment_r, &t.pigment_y, &t.pigment_b, &t.oil, &t.dryness})
    for (uint16_t q : *v) {
      raw.push_back(uint8_t(q & 0xff));
      raw.push_back(uint8_t(q >> 8));
    }
  return raw;
}

void unpack_tile(const uint8_t* raw, size_t n, TileData& t) {
  t.density.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t u = get_u32(raw + 4 * i);
    std::memcpy(&t.density[i], &u, 4);
  }
  const uint8_t* p = raw + 4 * n;
  for (auto* v : {&t.pigment_r, &t.pigment_y, &t.pigment_b, &t.oil, &t.dryness}) {
    v->resize(n);
    for (size_t i = 0; i < n; ++i) (*v)[i] = uint16_t(p[2 * i] | (p[2 * i + 1] << 8));
    p += 2 * n;
  }
}

// --- zip helpers -----------------------------------------------------------------------
struct ZipCloser {
  void operator()(zip_t* z) const {
    if (z) zip_discard(z);
  }
};

std::string zip_message(zip_error_t* e) {
  const char* s = zip_error_strerror(e);
  return s ? s : "unknown error";
}

// Downscaled copy (box filter) whose longest side is at most max_px.
std::vector<uint8_t> thumbnail(const Image& img, int max_px, int& tw, int& th) {
  const int longest = std::max(img.width, img.height);
  const int f = std::max(1, (longest + max_px - 1) / max_px);
  tw = std::max(1, img.width / f);
  th = std::max(1, img.height / f);
  std::vector<uint8_t> out(size_t(tw) * th * 4);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x)
      for (int c = 0; c < 4; ++c) {
        unsigned sum = 0;
        for (int j = 0; j < f; ++j)
          for (int i = 0; i < f; ++i) sum += img.at(x * f + i, y * f + j)[c];
        out[(size_t(y) * tw + x) * 4 + c] = uint8_t((sum + unsigned(f * f) / 2) / unsigned(f * f));
      }
  return out;
}

std::vector<uint8_t> read_entry(zip_t* za, zip_int64_t idx, const std::string& name, const std::string& what,
                                uint64_t max_bytes) {
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(za, zip_uint64_t(idx), 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE))
    WB_THROW(what + ": cannot read entry '" + name + "' of the archive");
  if (st.size > max_bytes)
    WB_THROW(what + ": entry '" + name + "' declares " + std::to_string(st.size) + " bytes uncompressed, more than the " +
             std::to_string(max_bytes) + " bytes allowed (refused before reading)");
  zip_file_t* f = zip_fopen_index(za, zip_uint64_t(idx), 0);
  if (!f) WB_THROW(what + ": cannot open entry '" + name + "': " + zip_strerror(za));
  std::vector<uint8_t> b(size_t(st.size));
  const zip_int64_t got = b.empty() ? 0 : zip_fread(f, b.data(), b.size());
  std::string err = got < 0 ? zip_file_strerror(f) : "";
  zip_fclose(f);
  if (got < 0) WB_THROW(what + ": entry '" + name + "' is damaged (" + err + ")");
  if (uint64_t(got) != st.size) WB_THROW(what + ": entry '" + name + "' is truncated");
  return b;
}

}  // namespace

// --- the volume entry ----------------------------------------------------------------------

std::vector<uint8_t> encode_volume(const TileStore& canvas) {
  const CanvasDims d = canvas.dims();
  const std::vector<int> ids = canvas.allocated_tile_ids();
  std::vector<std::vector<uint8_t>> blobs;
  blobs.reserve(ids.size());
  std::vector<uint8_t> head(kVolumeMagic, kVolumeMagic + 8);
  put_u32(head, kVolumeFormatVersion);
  put_u32(head, 0);  // flags
  put_u32(head, uint32_t(d.width));
  put_u32(head, uint32_t(d.height));
  put_u32(head, uint32_t(d.depth));
  put_u32(head, uint32_t(kTileSize));
  put_u32(head, uint32_t(kPaintFieldCount));
  put_u32(head, uint32_t(ids.size()));
  uint64_t offset = 0;
  for (int id : ids) {
    const TileData t = canvas.read_tile(id);
    const std::vector<uint8_t> raw = pack_tile(t);
    std::vector<uint8_t> z(ZSTD_compressBound(raw.size()));
    const size_t zn = ZSTD_compress(z.data(), z.size(), raw.data(), raw.size(), 3);
    if (ZSTD_isError(zn)) WB_THROW(std::string("volume: zstd compression failed: ") + ZSTD_getErrorName(zn));
    z.resize(zn);
    put_u32(head, uint32_t(t.tile_x));
    put_u32(head, uint32_t(t.tile_y));
    put_u64(head, offset);
    put_u64(head, uint64_t(zn));
    put_u32(head, crc(z.data(), z.size()));
    offset += zn;
    blobs.push_back(std::move(z));
  }
  put_u32(head, crc(head.data(), head.size()));
  for (auto& b : blobs) head.insert(head.end(), b.begin(), b.end());
  return head;
}

TileStore decode_volume(const uint8_t* p, size_t size, const Device& device, const std::string& what,
                        const LoadLimits& limits, const char* entry) {
  const std::string w = what + ": " + (entry == kPaletteEntry ? "palette" : "paint volume") + " (" + entry + ")";
  if (size < kFixedHeader || std::memcmp(p, kVolumeMagic, 8) != 0) WB_THROW(w + " has no volume header (wrong magic)");
  const uint32_t version = get_u32(p + 8);
  if (version > kVolumeFormatVersion)
    WB_THROW(w + " was written by a newer wetbrush (volume format version " + std::to_string(version) +
             "; this build reads up to version " + std::to_string(kVolumeFormatVersion) + "): update wetbrush");
  if (version == 0) WB_THROW(w + ": invalid format version 0");
  const uint32_t width = get_u32(p + 16), height = get_u32(p + 20), depth = get_u32(p + 24);
  const uint32_t tile = get_u32(p + 28), fields = get_u32(p + 32), count = get_u32(p + 36);
  const size_t header = kFixedHeader + size_t(count) * kEntryBytes + 4;
  if (width == 0 || height == 0 || depth == 0 || width > 65536 || height > 65536 || depth > 1024)
    WB_THROW(w + ": canvas size " + std::to_string(width) + " x " + std::to_string(height) + " x " +
             std::to_string(depth) + " out of range");
  if (uint64_t(width) * height > uint64_t(kMaxCanvasCells))
    WB_THROW(w + ": canvas " + std::to_string(width) + " x " + std::to_string(height) + " has more than " +
             std::to_string(kMaxCanvasCells) + " cells (16384 x 16384): refused");
  const uint64_t max_tiles = uint64_t((width + kTileSize - 1) / kTileSize) * ((height + kTileSize - 1) / kTileSize);
  if (count > max_tiles) WB_THROW(w + ": more tiles (" + std::to_string(count) + ") than the canvas has");
  if (header > size) WB_THROW(w + " is truncated (tile table incomplete)");
  if (crc(p, header - 4) != get_u32(p + header - 4)) WB_THROW(w + ": header checksum mismatch (file damaged)");
  if (tile != uint32_t(kTileSize)) WB_THROW(w + ": tile size " + std::to_string(tile) + " unsupported");
  if (fields != uint32_t(kPaintFieldCount)) WB_THROW(w + ": " + std::to_string(fields) + " fields per cell, expected 6");
  // Every tile decodes to 16 x 16 x depth cells, whatever its compressed size: the paint the
  // table declares is known here, before anything is allocated or decompressed.
  const uint64_t tile_bytes = uint64_t(kTileSize) * kTileSize * depth * kCellBytes;
  const uint64_t paint_bytes = uint64_t(count) * tile_bytes;
  if (paint_bytes > limits.max_paint_bytes)
    WB_THROW(w + ": " + std::to_string(count) + " tiles of a " + std::to_string(depth) + "-cell-deep canvas hold " +
             std::to_string(paint_bytes >> 20) + " MiB of paint, more than the " +
             std::to_string(limits.max_paint_bytes >> 20) + " MiB a painting may hold (refused)");

  TileStore canvas(device, CanvasDims{int(width), int(height), int(depth)});
  const size_t n = size_t(canvas.tile_cells());
  const size_t raw_size = n * kCellBytes;
  std::vector<uint8_t> raw(raw_size);
  std::set<int> seen;
  const uint8_t* data = p + header;
  const uint64_t data_size = size - header;
  uint64_t next_off = 0;
  for (uint32_t k = 0; k < count; ++k) {
    const uint8_t* e = p + kFixedHeader + size_t(k) * kEntryBytes;
    const uint32_t tx = get_u32(e), ty = get_u32(e + 4);
    const uint64_t off = get_u64(e + 8), zn = get_u64(e + 16);
    const uint32_t sum = get_u32(e + 24);
    const std::string tn = "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + ")";
    if (tx >= uint32_t(canvas.tiles_x()) || ty >= uint32_t(canvas.tiles_y())) WB_THROW(w + ": " + tn + " outside the canvas");
    if (!seen.insert(int(ty) * canvas.tiles_x() + int(tx)).second) WB_THROW(w + ": " + tn + " stored twice");
    if (off > data_size || zn > data_size - off) WB_THROW(w + " is truncated (" + tn + " data missing)");
    // Tiles are stored back to back in table order: no two tiles share bytes, so each tile's
    // decompression is paid for by its own bytes in the file.
    if (off != next_off) WB_THROW(w + ": " + tn + " data overlaps another tile or leaves a gap (file damaged)");
    next_off = off + zn;
    if (crc(data + off, size_t(zn)) != sum) WB_THROW(w + ": " + tn + " checksum mismatch (file damaged)");
    const size_t got = ZSTD_decompress(raw.data(), raw.size(), data + off, size_t(zn));
    if (ZSTD_isError(got)) WB_THROW(w + ": " + tn + " does not decompress: " + ZSTD_getErrorName(got));
    if (got != raw_size) WB_THROW(w + ": " + tn + " has " + std::to_string(got) + " bytes, expected " + std::to_string(raw_size));
    TileData t;
    t.tile_x = int(tx);
    t.tile_y = int(ty);
    unpack_tile(raw.data(), n, t);
    for (float f : t.density)
      if (!std::isfinite(f) || f < 0.f) WB_THROW(w + ": " + tn + " holds an invalid density");
    canvas.write_tile(t);
  }
  return canvas;
}

// --- OpenRaster --------------------------------------------------------------------------

void save_painting(const std::string& path, const TileStore& canvas, const Image& merged,
                   const nlohmann::json& metadata, const SaveOptions& options) {
  WB_REQUIRE(merged.width > 0 && merged.height > 0 && merged.rgba.size() == size_t(merged.width) * merged.height * 4,
             path + ": save: the merged image is empty or malformed");
  WB_REQUIRE(options.thumbnail_px >= 16, "save: thumbnail size must be at least 16 pixels");
  // Everything is encoded first, so the file is written in one go.
  const std::vector<uint8_t> mimetype(kOraMimetype, kOraMimetype + std::strlen(kOraMimetype));
  const std::string stack_s =
      "<?xml version='1.0' encoding='UTF-8'?>\n<image version=\"0.0.5\" w=\"" + std::to_string(merged.width) +
      "\" h=\"" + std::to_string(merged.height) +
      "\" xres=\"127\" yres=\"127\">\n  <stack>\n    <layer name=\"paint\" src=\"data/paint.png\" x=\"0\" y=\"0\" "
      "opacity=\"1.0\" visibility=\"visible\" composite-op=\"svg:src-over\"/>\n  </stack>\n</image>\n";
  const std::vector<uint8_t> stack(stack_s.begin(), stack_s.end());
  const std::vector<uint8_t> png = encode_png8(merged.rgba.data(), merged.width, merged.height, 4);
  int tw = 0, th = 0;
  const std::vector<uint8_t> thumb_px = thumbnail(merged, options.thumbnail_px, tw, th);
  const std::vector<uint8_t> thumb = encode_png8(thumb_px.data(), tw, th, 4);
  const std::vector<uint8_t> volume = encode_volume(canvas);
  const std::vector<uint8_t> palette = options.palette ? encode_volume(*options.palette) : std::vector<uint8_t>{};
  nlohmann::json meta = metadata.is_null() ? nlohmann::json::object() : metadata;
  const std::string meta_s = meta.dump(2);
  const std::vector<uint8_t> meta_b(meta_s.begin(), meta_s.end());

  // Build the archive in memory.
  zip_error_t ze;
  zip_error_init(&ze);
  zip_source_t* src = zip_source_buffer_create(nullptr, 0, 0, &ze);
  if (!src) WB_THROW(path + ": save: " + zip_message(&ze));
  zip_source_keep(src);
  std::unique_ptr<zip_source_t, void (*)(zip_source_t*)> src_guard(src, zip_source_free);
  std::unique_ptr<zip_t, ZipCloser> za(zip_open_from_source(src, ZIP_TRUNCATE, &ze));
  if (!za) WB_THROW(path + ": save: " + zip_message(&ze));
  struct Entry {
    const char* name;
    const std::vector<uint8_t>* data;
    bool store;
  };
  // The mimetype comes first and uncompressed (OpenRaster spec); PNG and zstd data are already compressed.
  const Entry entries[] = {{"mimetype", &mimetype, true},          {"stack.xml", &stack, false},
                           {"data/paint.png", &png, true},         {"mergedimage.png", &png, true},
                           {"Thumbnails/thumbnail.png", &thumb, true}, {kVolumeEntry, &volume, true},
                           {kMetadataEntry, &meta_b, false},       {kPaletteEntry, &palette, true}};
  for (const Entry& e : entries) {
    if (e.data == &palette && !options.palette) continue;
    zip_source_t* s = zip_source_buffer(za.get(), e.data->data(), e.data->size(), 0);
    if (!s) WB_THROW(path + ": save: " + zip_strerror(za.get()));
    const zip_int64_t idx = zip_file_add(za.get(), e.name, s, ZIP_FL_ENC_UTF_8 | ZIP_FL_OVERWRITE);
    if (idx < 0) {
      zip_source_free(s);
      WB_THROW(path + ": save: " + zip_strerror(za.get()));
    }
    zip_set_file_compression(za.get(), zip_uint64_t(idx), e.store ? ZIP_CM_STORE : ZIP_CM_DEFLATE, 0);
  }
  if (zip_close(za.get()) != 0) WB_THROW(path + ": save: " + zip_strerror(za.get()));
  za.release();  // closed
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_source_stat(src, &st) != 0 || zip_source_open(src) != 0) WB_THROW(path + ": save: cannot read the archive back");
  std::vector<uint8_t> bytes(size_t(st.size));
  const zip_int64_t got = zip_source_read(src, bytes.data(), bytes.size());
  zip_source_close(src);
  if (got != zip_int64_t(bytes.size())) WB_THROW(path + ": save: cannot read the archive back");
  write_file_atomic(path, bytes, options.fault_hook);
}

Painting load_painting(const std::string& path, const Device& device, const LoadLimits& limits) {
  std::vector<uint8_t> file;
  try {
    file = read_file(path);
  } catch (const Error&) {
    WB_THROW(path + ": cannot open the painting file");
  }
  return load_painting_bytes(file.data(), file.size(), path, device, limits);
}

Painting load_painting_bytes(const uint8_t* bytes, size_t size, const std::string& path, const Device& device,
                             const LoadLimits& limits) {
  if (size == 0) WB_THROW(path + ": empty file, not an OpenRaster painting");
  static const uint8_t png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size >= 8 && std::memcmp(bytes, png_sig, 8) == 0)
    WB_THROW(path + ": this is a PNG image, not an OpenRaster painting (.ora)");

  zip_error_t ze;
  zip_error_init(&ze);
  zip_source_t* src = zip_source_buffer_create(bytes, size, 0, &ze);
  if (!src) WB_THROW(path + ": " + zip_message(&ze));
  zip_t* raw = zip_open_from_source(src, ZIP_RDONLY | ZIP_CHECKCONS, &ze);
  if (!raw) {
    const int code = zip_error_code_zip(&ze);
    zip_source_free(src);
    if (code == ZIP_ER_NOZIP)
      WB_THROW(path + ": not an OpenRaster painting: not a ZIP archive (truncated, or another kind of file)");
    WB_THROW(path + ": not a readable OpenRaster painting: damaged ZIP archive (" + zip_message(&ze) + ")");
  }
  std::unique_ptr<zip_t, ZipCloser> za(raw);
  const zip_int64_t n = zip_get_num_entries(za.get(), 0);
  const char* first = n > 0 ? zip_get_name(za.get(), 0, 0) : nullptr;
  const zip_int64_t mt = zip_name_locate(za.get(), "mimetype", 0);
  if (mt < 0) WB_THROW(path + ": not an OpenRaster file: the archive has no 'mimetype' entry");
  const auto mime_b = read_entry(za.get(), mt, "mimetype", path, 256);
  const std::string mime(mime_b.begin(), mime_b.end());
  if (mime != kOraMimetype)
    WB_THROW(path + ": not an OpenRaster file: its mimetype is '" + mime + "', expected '" + kOraMimetype + "'");
  if (!first || std::string(first) != "mimetype")
    WB_THROW(path + ": malformed OpenRaster file: 'mimetype' is not the first entry");
  const zip_int64_t vi = zip_name_locate(za.get(), kVolumeEntry, 0);
  if (vi < 0)
    WB_THROW(path + ": an OpenRaster image without a wetbrush paint volume (" + kVolumeEntry +
             "), made by another program: wetbrush needs the 3D paint");
  const auto vol = read_entry(za.get(), vi, kVolumeEntry, path, limits.max_volume_entry_bytes);
  Painting p{decode_volume(vol.data(), vol.size(), device, path, limits), nlohmann::json::object(), std::nullopt};
  const zip_int64_t pi = zip_name_locate(za.get(), kPaletteEntry, 0);
  if (pi >= 0) {
    const auto pal = read_entry(za.get(), pi, kPaletteEntry, path, limits.max_volume_entry_bytes);
    p.palette.emplace(decode_volume(pal.data(), pal.size(), device, path, limits, kPaletteEntry));
  }
  const zip_int64_t mi = zip_name_locate(za.get(), kMetadataEntry, 0);
  if (mi >= 0) {
    const auto m = read_entry(za.get(), mi, kMetadataEntry, path, limits.max_metadata_bytes);
    try {
      p.metadata = nlohmann::json::parse(m.begin(), m.end());
    } catch (const nlohmann::json::exception& e) {
      WB_THROW(path + ": " + kMetadataEntry + " is not valid JSON: " + e.what());
    }
  }
  return p;
}

}  // namespace wb
