// Tile snapshots for undo: raw TileData fields packed back to back, zstd level 1 (fast; the
// empty upper layers of a tile compress to almost nothing).
#include "core/io/undo_tiles.h"

#include <zstd.h>

#include <algorithm>
#include <cstring>

#include "core/exec/error.h"

namespace wb {
namespace {

template <class T>
void append(std::vector<uint8_t>& out, const std::vector<T>& v) {
  const size_t at = out.size();
  out.resize(at + v.size() * sizeof(T));
  std::memcpy(out.data() + at, v.data(), v.size() * sizeof(T));
}

template <class T>
void take(const std::vector<uint8_t>& in, size_t& at, std::vector<T>& v, size_t n) {
  WB_REQUIRE(at + n * sizeof(T) <= in.size(), "undo tile snapshot: truncated data");
  v.resize(n);
  std::memcpy(v.data(), in.data() + at, n * sizeof(T));
  at += n * sizeof(T);
}

bool tile_present(const TileStore& canvas, int tile_id) {
  const auto ids = canvas.allocated_tile_ids();
  return std::find(ids.begin(), ids.end(), tile_id) != ids.end();
}

}  // namespace

TileSnapshot snapshot_tile(const TileStore& canvas, int tile_id) {
  TileSnapshot s;
  s.tile_id = tile_id;
  s.present = tile_present(canvas, tile_id);
  s.clock = canvas.drying_clock();
  if (!s.present) return s;
  const TileData d = canvas.read_tile(tile_id);
  std::vector<uint8_t> raw;
  raw.reserve(size_t(canvas.tile_cells()) * kCellBytes);
  append(raw, d.density);
  append(raw, d.pigment_r);
  append(raw, d.pigment_y);
  append(raw, d.pigment_b);
  append(raw, d.oil);
  append(raw, d.dryness);
  s.zdata.resize(ZSTD_compressBound(raw.size()));
  const size_t n = ZSTD_compress(s.zdata.data(), s.zdata.size(), raw.data(), raw.size(), 1);
  if (ZSTD_isError(n)) WB_THROW(std::string("undo tile snapshot: zstd: ") + ZSTD_getErrorName(n));
  s.zdata.resize(n);
  s.zdata.shrink_to_fit();
  return s;
}

void restore_tile(TileStore& canvas, const TileSnapshot& snap) {
  const size_t cells = size_t(canvas.tile_cells());
  TileData d;
  d.tile_x = snap.tile_id % canvas.tiles_x();
  d.tile_y = snap.tile_id / canvas.tiles_x();
  if (!snap.present) {
    if (!tile_present(canvas, snap.tile_id)) return;
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
  const int tx0 = std::max(0, x0 / kTileSize), ty0 = std::max(0, y0 / kTileSize);
  const int tx1 = std::min(canvas.tiles_x() - 1, (std::max(x1, 1) - 1) / kTileSize);
  const int ty1 = std::min(canvas.tiles_y() - 1, (std::max(y1, 1) - 1) / kTileSize);
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) {
      const int id = ty * canvas.tiles_x() + tx;
      if (!before_.count(id)) before_.emplace(id, snapshot_tile(canvas, id));
    }
}

TileDiff StrokeTileRecorder::finish(const TileStore& canvas) {
  TileDiff diff;
  std::vector<int> ids;
  for (const auto& [id, snap] : before_) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  for (int id : ids) {
    TileSnapshot now = snapshot_tile(canvas, id);
    TileSnapshot& was = before_[id];
    // Same compressor, same level, same input: equal bytes exactly when the tile is unchanged.
    if (now.present == was.present && now.zdata == was.zdata) continue;
    diff.before.push_back(std::move(was));
    diff.after.push_back(std::move(now));
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
