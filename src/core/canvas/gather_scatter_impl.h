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

/// Cells of a window row a gather or scatter takes together: on the CPU the row's run within one
/// tile (kTileSize cells, contiguous in the tile: one lookup of the tile's slot, no division a
/// cell); on CUDA one cell, a thread each.
#if defined(__CUDACC__)
inline constexpr int kRowRun = 1;
#else
inline constexpr int kRowRun = kTileSize;
#endif

WB_HD WB_INLINE int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/// A part of a window row within one tile-aligned run of kRowRun canvas columns: window cells
/// i0 .. i0 + len - 1, canvas columns cx .. cx + len - 1 of row cy, layer cz. The first
/// `on_canvas` of them lie on the canvas (all in one tile); where that tile is allocated
/// (at0 >= 0) they are pool cells at0 .. of slot `slot`.
struct WindowRun {
  int64_t i0, at0;
  int32_t slot;
  int len, on_canvas, cx, cy, cz;
  /// The cells with a place in the pool.
  WB_HD int in_pool() const { return at0 >= 0 ? on_canvas : 0; }
};

/// fn(run) for each WindowRun of the window.
template <typename F>
void for_window_runs(const TileStoreView& t, const PaintWindowView& w, F fn) {
  const int first = floor_div(w.ox, kRowRun), runs = floor_div(w.ox + w.nx - 1, kRowRun) - first + 1;
  const int64_t rows = int64_t(w.ny) * w.nz;
  parallel_for(
      rows * runs,
      [=] WB_HD(int64_t u) {
        // 32-bit divisions (a GPU emulates 64-bit ones): a window's cells number fewer than 2^32
        // (PaintWindow requires it), and its runs no more than its cells and rows.
        const uint32_t row = uint32_t(u) / uint32_t(runs), ny = uint32_t(w.ny);
        const int r = int(uint32_t(u) - row * uint32_t(runs));
        WindowRun run;
        run.cy = int(row % ny) + w.oy, run.cz = int(row / ny) + w.oz;
        run.cx = imax(w.ox, (first + r) * kRowRun);
        run.len = imin(w.ox + w.nx, (first + r + 1) * kRowRun) - run.cx;
        run.i0 = int64_t(row) * w.nx + (run.cx - w.ox);
        // A run is tile-aligned: all of it lies left of the canvas or none; past its last column
        // the rest is off it.
        run.on_canvas = t.inside(run.cx, run.cy, run.cz) ? imin(run.len, t.width - run.cx) : 0;
        const CanvasCellRef c = locate(t, run.cx, run.cy, run.cz);
        run.at0 = c.at;
        run.slot = c.slot;
        fn(run);
      },
      kMinParallelSize / kRowRun);
}
}  // namespace detail

void tiles_gather_window(TileStoreView t, PaintWindowView w) {
  detail::for_window_runs(t, w, [=] WB_HD(const detail::WindowRun& run) {
    const int on = run.in_pool();
    for (int k = 0; k < on; ++k) {
      const int64_t i = run.i0 + k, at = run.at0 + k;
      w.density[i] = t.density[at];
      w.pigment_r[i] = decode_unorm16(t.pigment_r[at]);
      w.pigment_y[i] = decode_unorm16(t.pigment_y[at]);
      w.pigment_b[i] = decode_unorm16(t.pigment_b[at]);
      w.oil[i] = decode_unorm16(t.oil[at]);
      w.dryness[i] = t.dryness_at(run.slot, at);
    }
    for (int64_t i = run.i0 + on; i < run.i0 + run.len; ++i)  // off the canvas, or in a tile with no paint
      w.density[i] = w.pigment_r[i] = w.pigment_y[i] = w.pigment_b[i] = w.oil[i] = w.dryness[i] = 0.f;
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
  // A run's cells on the canvas lie in one tile, allocated or not: it is painted when any is.
  detail::for_window_runs(t, w, [=] WB_HD(const detail::WindowRun& run) {
    bool painted = false;
    for (int64_t i = run.i0; i < run.i0 + run.on_canvas; ++i) painted |= w.density[i] != 0.f;
    const int f = (run.cy / kTileSize - ty0) * ntx + (run.cx / kTileSize - tx0);
    if (painted && flags[f] == 0) atomic_or(&flags[f], 1);
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
  detail::for_window_runs(t, w, [=] WB_HD(const detail::WindowRun& run) {
    // The density overwritten and written, for the canvas's running mass.
    const int on = run.in_pool();
    for (int k = 0; k < on; ++k) {
      const int64_t i = run.i0 + k, at = run.at0 + k;
      before[i] = t.density[at];
      after[i] = w.density[i];
      t.density[at] = w.density[i];
      t.pigment_r[at] = encode_unorm16(w.pigment_r[i]);
      t.pigment_y[at] = encode_unorm16(w.pigment_y[i]);
      t.pigment_b[at] = encode_unorm16(w.pigment_b[i]);
      t.oil[at] = encode_unorm16(w.oil[i]);
      t.dryness[at] = encode_unorm16(w.dryness[i]);
    }
    for (int64_t i = run.i0 + on; i < run.i0 + run.len; ++i) before[i] = after[i] = 0.f;  // off-canvas, or no tile
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
