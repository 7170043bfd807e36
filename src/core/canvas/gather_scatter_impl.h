// Gather and scatter between the sparse tiles and the dense active window (DESIGN
// step 3). Compiled once per backend; one launch per operation.
#pragma once
#include "core/canvas/ground.h"
#include "core/canvas/tile_store.h"
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"

namespace wb::WB_BACKEND_NS {

namespace detail {
struct CanvasCellRef {
  int64_t at = -1;    ///< offset into the pool, -1 when unallocated or off-canvas
  int32_t slot = -1;  ///< its tile's slot
};
WB_HD WB_INLINE CanvasCellRef locate(const TileStoreView& t, int cx, int cy, int cz) {
  CanvasCellRef r;
  if (!t.inside(cx, cy, cz)) return r;
  const int tile = (cy / kTileSize) * t.tiles_x + cx / kTileSize;
  const int32_t slot = t.slot_of_tile[tile];
  if (slot < 0) return r;
  r.slot = slot;
  r.at = int64_t(slot) * t.tile_cells() + t.cell_offset(cx % kTileSize, cy % kTileSize, cz);
  return r;
}
/// A window's cells number fewer than 2^32 (PaintWindow requires it): two 32-bit divisions, a
/// fraction of the three 64-bit ones' cost (a GPU emulates those in software).
WB_HD WB_INLINE void decompose(const PaintWindowView& w, int64_t i, int& x, int& y, int& z) {
  const uint32_t t = uint32_t(i), nx = uint32_t(w.nx), ny = uint32_t(w.ny);
  const uint32_t row = t / nx, layer = row / ny;
  x = int(t - row * nx);
  y = int(row - layer * ny);
  z = int(layer);
}
}  // namespace detail

void tiles_gather_window(TileStoreView t, PaintWindowView w) {
  parallel_for(w.size(), [=] WB_HD(int64_t i) {
    int x, y, z;
    detail::decompose(w, i, x, y, z);
    const auto c = detail::locate(t, x + w.ox, y + w.oy, z + w.oz);
    if (c.at < 0) {
      w.density[i] = w.pigment_r[i] = w.pigment_y[i] = w.pigment_b[i] = w.oil[i] = w.dryness[i] = 0.f;
      return;
    }
    w.density[i] = t.density[c.at];
    w.pigment_r[i] = decode_unorm16(t.pigment_r[c.at]);
    w.pigment_y[i] = decode_unorm16(t.pigment_y[c.at]);
    w.pigment_b[i] = decode_unorm16(t.pigment_b[c.at]);
    w.oil[i] = decode_unorm16(t.oil[c.at]);
    w.dryness[i] = t.dryness_at(c.slot, c.at);
  });
}

void tiles_settle_window(TileStoreView t, int tx0, int ty0, int ntx, int nty) {
  // A layer of a tile a thread: a tile up to date (every tile, once the first layer set it, at a
  // step's scatter where nothing dried) costs a read.
  const int64_t layer = int64_t(kTileSize) * kTileSize, layers = int64_t(ntx) * nty * t.depth;
  parallel_for(layers, [=] WB_HD(int64_t k) {
    const int64_t f = k / t.depth;
    const int tile = (ty0 + int(f / ntx)) * t.tiles_x + tx0 + int(f % ntx);
    const int32_t slot = t.slot_of_tile[tile];
    if (slot < 0 || !(t.clock - t.dried_to[slot] > 0.f)) return;
    const int64_t at0 = int64_t(slot) * t.tile_cells() + (k % t.depth) * layer;
    for (int64_t at = at0; at < at0 + layer; ++at) t.dryness[at] = encode_unorm16(t.dryness_at(slot, at));
  });
  // Then each tile is up to date (after every cell has read its old clock).
  parallel_for(int64_t(ntx) * nty, [=] WB_HD(int64_t f) {
    const int32_t slot = t.slot_of_tile[(ty0 + int(f / ntx)) * t.tiles_x + tx0 + int(f % ntx)];
    if (slot >= 0) t.dried_to[slot] = t.clock;
  });
}

void tiles_allocate_painted(TileStoreView t, PaintWindowView w, int tx0, int ty0, int ntx, int nty, int32_t* flags,
                            TileSlots slots) {
  parallel_for(w.size(), [=] WB_HD(int64_t i) {
    if (w.density[i] == 0.f) return;
    int x, y, z;
    detail::decompose(w, i, x, y, z);
    const int cx = x + w.ox, cy = y + w.oy, cz = z + w.oz;
    if (!t.inside(cx, cy, cz)) return;
    const int f = (cy / kTileSize - ty0) * ntx + (cx / kTileSize - tx0);
    if (flags[f] == 0) atomic_or(&flags[f], 1);
  });
  // A painted tile without a slot takes the next: the pool holds them (TileStore::scatter sizes
  // it for every tile of the window), and its slot is empty and up to date with the clock.
  parallel_for(int64_t(ntx) * nty, [=] WB_HD(int64_t f) {
    const int tile = (ty0 + int(f / ntx)) * t.tiles_x + tx0 + int(f % ntx);
    if (!flags[f] || slots.slot_of_tile[tile] >= 0) return;
    const int32_t s = atomic_add(slots.used, int32_t(1));
    slots.slot_of_tile[tile] = s;
    slots.tile_of_slot[s] = tile;
    t.dried_to[s] = t.clock;
  });
}

void tiles_scatter_window(TileStoreView t, PaintWindowView w, float* before, float* after) {
  parallel_for(w.size(), [=] WB_HD(int64_t i) {
    int x, y, z;
    detail::decompose(w, i, x, y, z);
    const auto c = detail::locate(t, x + w.ox, y + w.oy, z + w.oz);
    // The density overwritten and written, for the canvas's running mass.
    before[i] = c.at >= 0 ? t.density[c.at] : 0.f;
    after[i] = c.at >= 0 ? w.density[i] : 0.f;
    if (c.at < 0) return;  // off-canvas, or an unallocated tile that received no paint
    t.density[c.at] = w.density[i];
    t.pigment_r[c.at] = encode_unorm16(w.pigment_r[i]);
    t.pigment_y[c.at] = encode_unorm16(w.pigment_y[i]);
    t.pigment_b[c.at] = encode_unorm16(w.pigment_b[i]);
    t.oil[c.at] = encode_unorm16(w.oil[i]);
    t.dryness[c.at] = encode_unorm16(w.dryness[i]);
  });
}

void tiles_dry_all(TileStoreView t, int64_t cells) {
  parallel_for(cells, [=] WB_HD(int64_t i) {
    if (t.density[i] > 0.f) t.dryness[i] = 65535;
  });
}

/// Lays the woven ground into every cell of the canvas (all tiles allocated, slot = tile id):
/// dried primer up to weave_height, nothing above it. One thread a column: the weave's height
/// (its threads' cosines) once, then the column's cells.
void tiles_lay_weave(TileStoreView t, WeaveField w, int64_t columns) {
  constexpr int64_t kTileColumns = int64_t(kTileSize) * kTileSize;
  parallel_for(columns, [=] WB_HD(int64_t i) {
    const int32_t slot = int32_t(i / kTileColumns);
    const int64_t in = i - int64_t(slot) * kTileColumns;
    const int lx = int(in % kTileSize), ly = int(in / kTileSize);
    const int x = (slot % t.tiles_x) * kTileSize + lx, y = (slot / t.tiles_x) * kTileSize + ly;
    const bool on = x < t.width && y < t.height;
    const float h = on ? weave_height(w, float(x) + 0.5f, float(y) + 0.5f) : 0.f;
    const uint16_t r = encode_unorm16(w.ryb.x), yl = encode_unorm16(w.ryb.y), b = encode_unorm16(w.ryb.z);
    const uint16_t oil = encode_unorm16(w.oil);
    for (int z = 0; z < t.depth; ++z) {
      const int64_t c = int64_t(slot) * t.tile_cells() + t.cell_offset(lx, ly, z);
      const float d = on ? ground_density(h, z) : 0.f;
      const bool paint = d > 0.f;
      t.density[c] = d;
      t.pigment_r[c] = paint ? r : 0;
      t.pigment_y[c] = paint ? yl : 0;
      t.pigment_b[c] = paint ? b : 0;
      t.oil[c] = paint ? oil : 0;
      t.dryness[c] = paint ? 65535 : 0;
    }
  });
}

}  // namespace wb::WB_BACKEND_NS
