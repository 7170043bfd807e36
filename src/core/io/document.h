// Painting files (DESIGN "Files"): OpenRaster (.ora: a ZIP with mimetype, stack.xml, PNG
// layers, mergedimage.png, Thumbnails/thumbnail.png), which MyPaint, Krita and GIMP open as
// the flat rendered painting, plus the sparse 3D paint volume that wetbrush needs as the extra
// entry wetbrush/volume.bin (zstd per tile, format version, CRC32 checksums) and the metadata
// as wetbrush/metadata.json. Saves are atomic. Format: docs/FORMATS.md "Painting files".
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/canvas/ground.h"
#include "core/canvas/tile_store.h"
#include "core/render/renderer.h"

namespace wb {

/// Version of wetbrush/volume.bin this build writes and the newest it reads.
inline constexpr uint32_t kVolumeFormatVersion = 1;
inline constexpr const char* kOraMimetype = "image/openraster";
inline constexpr const char* kVolumeEntry = "wetbrush/volume.bin";
inline constexpr const char* kMetadataEntry = "wetbrush/metadata.json";
/// The studio's palette (a small canvas of its own), in the volume entry's format.
inline constexpr const char* kPaletteEntry = "wetbrush/palette.bin";

struct Painting {
  TileStore canvas;
  nlohmann::json metadata;
  std::optional<TileStore> palette;  ///< the palette saved with the painting, if any
};

struct SaveOptions {
  /// Called at "partial-write" (half the bytes are in the temporary file) and "before-rename";
  /// a hook that throws makes the save fail there (tests of atomicity).
  std::function<void(const std::string& stage)> fault_hook;
  int thumbnail_px = 256;  ///< longest side of Thumbnails/thumbnail.png
  const TileStore* palette = nullptr;  ///< saved as wetbrush/palette.bin when given
};

/// Writes the painting atomically: the whole file goes to a temporary file in the same
/// directory, which is fsync'ed and renamed over `path`, then the directory is fsync'ed.
/// A failure at any point leaves an existing file at `path` untouched. `merged` is the
/// rendered painting (any size; usually one pixel per canvas cell).
void save_painting(const std::string& path, const TileStore& canvas, const Image& merged,
                   const nlohmann::json& metadata, const SaveOptions& options = {});

/// What reading an untrusted painting may cost (docs/RELIABILITY.md "Resource limits"). Every
/// size is checked against these before the memory is allocated, so a hostile file is refused
/// in bounded time and memory; a file within them reads as before.
struct LoadLimits {
  /// Uncompressed size of the volume entry as the ZIP declares it (it is stored, so a real one
  /// is about as large as its compressed tiles).
  uint64_t max_volume_entry_bytes = uint64_t(1) << 30;
  /// Uncompressed size of wetbrush/metadata.json.
  uint64_t max_metadata_bytes = uint64_t(16) << 20;
  /// Decoded paint: tiles x 16 x 16 x depth cells x 14 bytes (also never more than the whole
  /// canvas the file declares, since a tile may be stored once). As much as a woven ground may
  /// lay (kMaxGroundBytes), so that a primed canvas always opens again.
  uint64_t max_paint_bytes = kMaxGroundBytes;
};

/// Reads a painting onto `device`. Truncated, corrupted, foreign or newer-version files are
/// rejected with a wb::Error that names the file and what is wrong; files beyond `limits` are
/// refused before their memory is allocated.
Painting load_painting(const std::string& path, const Device& device, const LoadLimits& limits = {});
/// The same from the file's bytes in memory; `what` names it in messages.
Painting load_painting_bytes(const uint8_t* bytes, size_t size, const std::string& what, const Device& device,
                             const LoadLimits& limits = {});

/// The volume entry alone (exposed for tests and tools).
std::vector<uint8_t> encode_volume(const TileStore& canvas);
/// `entry` names the archive entry in messages (the volume or the palette).
TileStore decode_volume(const uint8_t* bytes, size_t size, const Device& device, const std::string& what,
                        const LoadLimits& limits = {}, const char* entry = kVolumeEntry);

}  // namespace wb
