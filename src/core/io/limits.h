// Resource limits on untrusted files (stroke files, painting files, PNG images): every size a
// file declares is checked against these before memory is allocated for it, so a hostile file
// is refused with a clear message in bounded time and memory. docs/RELIABILITY.md lists them
// with the tests that show each one.
#pragma once
#include <cstdint>

namespace wb {

/// Largest canvas area (width x height cells) a file may declare: the whole-canvas picture a
/// replay or a save renders is 4 bytes a cell, so this bounds it at 1 GiB (16384 x 16384, or
/// 65536 x 4096 cells).
inline constexpr int64_t kMaxCanvasCells = int64_t(1) << 28;

/// Largest decoded PNG (rows x row bytes) read from a file: 1 GiB, e.g. 16384 x 16384 RGBA.
inline constexpr uint64_t kMaxPngDecodedBytes = uint64_t(1) << 30;

}  // namespace wb
