// Tile snapshots for undo: raw TileData fields packed back to back, zstd level 1 (fast; the
// empty upper layers of a tile compress to almost nothing).
#include "core/io/undo_tiles.h"

#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <memory>

#include "core/exec/error.h"

namespace wb {
namespace {

/// Copies v's bytes into out at `at` and moves `at` past them.
template <class T>
void put(std::vector<uint8_t>& out, size_t& at, const std::vector<T>& v) {
  std::memcpy(out.data() + at, v.data(), v.size() * sizeof(T));
  at += v.size() * sizeof(T);
}

template <class T>
void take(const std::vector<uint8_t>& in, size_t& at, std::vector<T>& v, size_t n) {
  WB_REQUIRE(at + n * sizeof(T) <= in.size(), "undo tile snapshot: truncated data");
  v.resize(n);
  std::memcpy(v.data(), in.data() + at, n * sizeof(T));
  at += n * sizeof(T);
}

/// A thread's buffers for packing snapshots: a stroke's first step takes a hundred or more tiles
/// (the whole ground of a primed canvas under the brush's reach), each packed and compressed
/// without allocating or zeroing a tile's worth of memory, through one compression context.
struct Packer {
  std::vector<uint8_t> raw, packed;
  std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> cctx{ZSTD_createCCtx(), ZSTD_freeCCtx};
};

/// The tile's fields back to back, zstd level 1. Host work only: it may run on any thread.
std::vector<uint8_t> pack_tile(const TileData& d) {
  thread_local Packer k;
  if (!k.cctx) WB_THROW("undo tile snapshot: zstd could not make a compression context");
  k.raw.resize(d.density.size() * kCellBytes);
  size_t at = 0;
  put(k.raw, at, d.density);
  put(k.raw, at, d.pigment_r);
  put(k.raw, at, d.pigment_y);
  put(k.raw, at, d.pigment_b);
  put(k.raw, at, d.oil);
  put(k.raw, at, d.dryness);
  WB_REQUIRE(at == k.raw.size(), "undo tile snapshot: the tile's fields do not fill it");
  k.packed.resize(ZSTD_compressBound(k.raw.size()));
  const size_t n = ZSTD_compressCCtx(k.cctx.get(), k.packed.data(), k.packed.size(), k.raw.data(), k.raw.size(), 1);
  if (ZSTD_isError(n)) WB_THROW(std::string("undo tile snapshot: zstd: ") + ZSTD_getErrorName(n));
  return std::vector<uint8_t>(k.packed.begin(), k.packed.begin() + std::ptrdiff_t(n));
}

/// The snapshot of tile_id without its data: whether it is allocated, and the clock.
TileSnapshot snapshot_header(const TileStore& canvas, int tile_id) {
  TileSnapshot s;
  s.tile_id = tile_id;
  s.present = canvas.tile_allocated(tile_id);
  s.clock = canvas.drying_clock();
  return s;
}

}  // namespace

std::vector<TileSnapshot> snapshot_tiles(const TileStore& canvas, const std::vector<int>& ids) {
  constexpr size_t kBatch = 32;  // 32 tiles read ahead: 3.7 MB at a depth of 32 cells
  std::vector<TileSnapshot> out(ids.size());
  // The calling thread's buffers, by reference: in the parallel loop the name of a thread_local
  // would be each worker's own.
  thread_local std::vector<TileData> batch;
  std::vector<TileData>& read = batch;
  if (read.size() < std::min(kBatch, ids.size())) read.resize(std::min(kBatch, ids.size()));
  for (size_t b = 0; b < ids.size(); b += kBatch) {
    const int64_t n = int64_t(std::min(kBatch, ids.size() - b));
    for (int64_t j = 0; j < n; ++j) {
      TileSnapshot& s = out[b + size_t(j)] = snapshot_header(canvas, ids[b + size_t(j)]);
      if (s.present) canvas.read_tile(s.tile_id, read[size_t(j)]);
    }
    std::exception_ptr failed;
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t j = 0; j < n; ++j) {
      TileSnapshot& s = out[b + size_t(j)];
      if (!s.present) continue;
      try {
        s.zdata = pack_tile(read[size_t(j)]);
      } catch (...) {
#pragma omp critical(wb_undo_snapshot)
        failed = std::current_exception();
      }
    }
    if (failed) std::rethrow_exception(failed);
  }
  return out;
}

TileSnapshot snapshot_tile(const TileStore& canvas, int tile_id) { return snapshot_tiles(canvas, {tile_id}).front(); }

std::vector<int> tile_ids_in_rect(const TileStore& canvas, int x0, int y0, int x1, int y1) {
  const int tx0 = std::max(0, x0 / kTileSize), ty0 = std::max(0, y0 / kTileSize);
  const int tx1 = std::min(canvas.tiles_x() - 1, (std::max(x1, 1) - 1) / kTileSize);
  const int ty1 = std::min(canvas.tiles_y() - 1, (std::max(y1, 1) - 1) / kTileSize);
  std::vector<int> ids;
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) ids.push_back(ty * canvas.tiles_x() + tx);
  return ids;
}

void restore_tile(TileStore& canvas, const TileSnapshot& snap) {
  const size_t cells = size_t(canvas.tile_cells());
  TileData d;
  d.tile_x = snap.tile_id % canvas.tiles_x();
  d.tile_y = snap.tile_id / canvas.tiles_x();
  if (!snap.present) {
    if (!canvas.tile_allocated(snap.tile_id)) return;
    d.density.assign(cells, 0.f);
    for (auto* v : {&d.pigment_r, &d.pigment_y, &d.pigment_b, &d.oil, &d.dryness}) v->assign(cells, 0);
    canvas.write_tile(d);
    return;
  }
  std::vector<uint8_t> raw(cells * kCellBytes);
  const size_t n = ZSTD_decompress(raw.data(), raw.size(), snap.zdata.data(), snap.zdata.size());
  if (ZSTD_isError(n) || n != raw.size()) WB_THROW("undo tile snapshot: corrupted data");
  size_t at = 0;
  take(raw, at, d.density, cells);
  for (auto* v : {&d.pigment_r, &d.pigment_y, &d.pigment_b, &d.oil, &d.dryness}) take(raw, at, *v, cells);
  const float since = float(canvas.drying_clock() - snap.clock);
  if (since > 0.f)
    for (size_t i = 0; i < cells; ++i)
      if (d.density[i] > 0.f) d.dryness[i] = encode_unorm16(with_drying(decode_unorm16(d.dryness[i]), since));
  canvas.write_tile(d);
}

size_t TileDiff::bytes() const {
  size_t b = 0;
  for (const auto* list : {&before, &after})
    for (const TileSnapshot& s : *list) b += s.zdata.size() + sizeof(TileSnapshot);
  return b;
}

void TileDiff::apply_before(TileStore& canvas) const {
  for (const TileSnapshot& s : before) restore_tile(canvas, s);
}
void TileDiff::apply_after(TileStore& canvas) const {
  for (const TileSnapshot& s : after) restore_tile(canvas, s);
}

void StrokeTileRecorder::capture_rect(const TileStore& canvas, int x0, int y0, int x1, int y1) {
  std::vector<int> ids = tile_ids_in_rect(canvas, x0, y0, x1, y1);
  std::erase_if(ids, [&](int id) { return before_.count(id) > 0; });
  for (TileSnapshot& s : snapshot_tiles(canvas, ids)) before_.emplace(s.tile_id, std::move(s));
}

TileDiff StrokeTileRecorder::finish(const TileStore& canvas) {
  TileDiff diff;
  std::vector<int> ids;
  for (const auto& [id, snap] : before_) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  std::vector<TileSnapshot> now = snapshot_tiles(canvas, ids);
  for (TileSnapshot& after : now) {
    TileSnapshot& was = before_[after.tile_id];
    // Same compressor, same level, same input: equal bytes exactly when the tile is unchanged.
    if (after.present == was.present && after.zdata == was.zdata) continue;
    diff.before.push_back(std::move(was));
    diff.after.push_back(std::move(after));
  }
  before_.clear();
  return diff;
}

std::vector<TileSnapshot> StrokeTileRecorder::take_before() {
  std::vector<TileSnapshot> out;
  out.reserve(before_.size());
  for (auto& [id, snap] : before_) out.push_back(std::move(snap));
  std::sort(out.begin(), out.end(), [](const TileSnapshot& a, const TileSnapshot& b) { return a.tile_id < b.tile_id; });
  before_.clear();
  return out;
}

}  // namespace wb
