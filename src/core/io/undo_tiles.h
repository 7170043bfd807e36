// Tile snapshots for undo (the studio's whole-stroke undo, DESIGN "The canvas: sparse"): the
// tiles a stroke may touch are captured before it runs, compared after it, and only those
// that changed are kept, zstd-compressed, as a before/after pair. Qt-free.
#pragma once
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/canvas/tile_store.h"

namespace wb {

/// One tile as it was: absent (never allocated) or its stored fields, zstd-compressed.
struct TileSnapshot {
  int tile_id = -1;
  bool present = false;
  double clock = 0.0;          ///< the canvas's drying clock when taken
  std::vector<uint8_t> zdata;  ///< compressed TileData fields (empty when absent)
};

/// Compresses one tile of the store (an unallocated tile gives present = false).
TileSnapshot snapshot_tile(const TileStore& canvas, int tile_id);
/// snapshot_tile of each of `ids`: the tiles read on the calling thread (a device's copies stay on
/// its stream, after its kernels), compressed on every core.
std::vector<TileSnapshot> snapshot_tiles(const TileStore& canvas, const std::vector<int>& ids);
/// Ids of the canvas's tiles overlapping the cells [x0, x1) x [y0, y1), row by row.
std::vector<int> tile_ids_in_rect(const TileStore& canvas, int x0, int y0, int x1, int y1);
/// Writes the snapshot back, its paint with the drying the canvas has done since it was taken
/// (undo removes a stroke; it does not make the rest of the painting wetter). An absent tile is
/// written as an empty (all-zero) tile when it
/// is allocated now, and left alone otherwise.
void restore_tile(TileStore& canvas, const TileSnapshot& snap);

/// Before/after of the tiles one stroke changed.
struct TileDiff {
  std::vector<TileSnapshot> before, after;
  size_t bytes() const;
  bool empty() const { return before.empty(); }
  void apply_before(TileStore& canvas) const;
  void apply_after(TileStore& canvas) const;
};

/// Collects the "before" of every tile a stroke may touch: call capture_rect() with the
/// canvas rectangle that the next simulation step may change, before running it; finish()
/// compares with the canvas now and keeps only the tiles that differ.
class StrokeTileRecorder {
 public:
  /// Captures the tiles overlapping [x0, x1) x [y0, y1) (cells) not captured yet.
  void capture_rect(const TileStore& canvas, int x0, int y0, int x1, int y1);
  bool active() const { return !before_.empty(); }
  size_t captured() const { return before_.size(); }
  /// The diff of the captured tiles against the canvas now; resets the recorder.
  TileDiff finish(const TileStore& canvas);
  /// The captured tiles as they were, in tile order, without reading the canvas (a stroke that
  /// cannot be finished goes back to them); resets the recorder.
  std::vector<TileSnapshot> take_before();
  void reset() { before_.clear(); }

 private:
  std::unordered_map<int, TileSnapshot> before_;
};

}  // namespace wb
