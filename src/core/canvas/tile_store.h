// The sparse canvas: width x height x depth cells stored as columns of 16 x 16 x depth
// cells ("tiles"), allocated on first write from a pool that grows geometrically.
// An empty canvas costs only the tile index. Storage per cell (14 bytes):
//   density  float32  -- mass must survive any number of window moves exactly
//   R, Y, B  unorm16   -- pigment mixes in small steps; 8 bits would band and drift
//   oil      unorm16
//   dryness  unorm16   -- 1/65535 resolution; drying rates are far coarser per step
// Paint dries everywhere at once without a pass over the canvas: the canvas keeps a drying
// clock (the dryness every painted cell has gained so far) and each tile the clock's value when
// its stored dryness was last brought up to date; readers add the difference.
// See docs/ARCHITECTURE.md ("The sparse canvas") for the reasoning.
#pragma once
#include <cstdint>
#include <vector>

#include "core/canvas/ground.h"
#include "core/canvas/paint_fields.h"
#include "core/canvas/window.h"
#include "core/exec/buffer.h"
#include "core/exec/dispatch.h"
#include "core/exec/workspace.h"

namespace wb {

inline constexpr int kTileSize = 16;
/// Bytes a cell of paint takes in the pool and in a painting's volume: the density (float) and
/// four pigment/oil fields and the dryness (unorm16 each).
inline constexpr int kCellBytes = int(sizeof(float) + 5 * sizeof(uint16_t));

struct CanvasDims {
  int width = 4096;
  int height = 4096;
  int depth = 64;
  bool operator==(const CanvasDims& o) const { return width == o.width && height == o.height && depth == o.depth; }
};

WB_HD WB_INLINE uint16_t encode_unorm16(float v) {
  v = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
  return uint16_t(v * 65535.f + 0.5f);
}
WB_HD WB_INLINE float decode_unorm16(uint16_t q) { return float(q) * (1.f / 65535.f); }

/// Dryness `d` of paint after `lag` more drying: drying is linear and stops at 1, so drying owed
/// can be added late, in one go (the canvas's drying clock, TileStore::advance_drying).
WB_HD WB_INLINE float with_drying(float d, float lag) { return lag > 0.f ? (d + lag < 1.f ? d + lag : 1.f) : d; }

/// POD view of the tile pool, passed by value to kernels.
struct TileStoreView {
  const int32_t* slot_of_tile;  ///< tiles_x * tiles_y entries, -1 = not allocated
  float* density;               ///< slot * tile_cells + cell
  uint16_t* pigment_r;
  uint16_t* pigment_y;
  uint16_t* pigment_b;
  uint16_t* oil;
  uint16_t* dryness;
  float* dried_to;              ///< per slot: the drying clock its stored dryness includes
  float clock;                  ///< the canvas's drying clock (TileStore::advance_drying)
  int width, height, depth;
  int tiles_x, tiles_y;
  WB_HD int64_t tile_cells() const { return int64_t(kTileSize) * kTileSize * depth; }
  /// Dryness of the cell at pool offset `at` of slot `slot`, with the drying its tile has not
  /// stored yet: paint (density > 0) gains clock - dried_to, up to 1.
  WB_HD float dryness_at(int32_t slot, int64_t at) const {
    const float d = decode_unorm16(dryness[at]);
    return density[at] > 0.f ? with_drying(d, clock - dried_to[slot]) : d;
  }
  WB_HD int64_t cell_offset(int lx, int ly, int z) const { return (int64_t(z) * kTileSize + ly) * kTileSize + lx; }
  WB_HD bool inside(int x, int y, int z) const {
    return x >= 0 && y >= 0 && z >= 0 && x < width && y < height && z < depth;
  }
};

/// The slot table as the device allocates it (tiles_allocate_painted).
struct TileSlots {
  int32_t* slot_of_tile;
  int32_t* tile_of_slot;
  int32_t* used;  ///< slots in use
};

/// The host copy of one tile, as stored.
struct TileData {
  int tile_x = 0, tile_y = 0;
  std::vector<float> density;
  std::vector<uint16_t> pigment_r, pigment_y, pigment_b, oil, dryness;
};

class TileStore {
 public:
  TileStore(const Device& device, CanvasDims dims);

  const Device& device() const { return device_; }
  CanvasDims dims() const { return dims_; }
  int tiles_x() const { return tiles_x_; }
  int tiles_y() const { return tiles_y_; }
  int64_t tile_cells() const { return int64_t(kTileSize) * kTileSize * dims_.depth; }

  /// Fills the window from the tiles at the window's origin (empty where unallocated or off-canvas).
  void gather(PaintWindow& window);
  /// Writes the window back; allocates the tiles that receive paint. Off-canvas cells are dropped.
  void scatter(PaintWindow& window);
  /// "Let it dry": every cell holding paint becomes fully dry (solid).
  void dry_all();
  /// Primes an empty canvas with a woven ground (ground.h): every tile is allocated and filled
  /// on the device with dried primer up to the weave's height.
  void lay_weave(const WeaveField& w);
  /// Every painted cell of the canvas gains `amount` of dryness (capped at 1), at the cost of
  /// one addition: the tiles catch up when read. The window's own cells are dried by the grid.
  void advance_drying(double amount);
  /// The drying clock: dryness gained by paint since the canvas was made.
  double drying_clock() const { return clock_; }
  /// Empties the canvas (keeps the pool's memory).
  void clear();
  /// Becomes a copy of `src` (same dimensions), copied on the device when both live on one: a
  /// brush change or an opened painting replaces the live canvas without a trip through the host.
  /// From another device the tiles come through the host, one at a time.
  void copy_from(const TileStore& src);

  /// Tiles allocated (a read of the device's slot count where its scatters allocated since the
  /// host last learnt it: see no_tiles for a step's question).
  int allocated_tiles() const;
  /// No tile is allocated, known without a read (the host's bound on the slots in use is 0).
  bool no_tiles() const { return bound_ == 0; }
  /// The device's count of slots in use, for a caller's step record ...
  const int32_t* tiles_used() const { return slots_used_dev_.data(); }
  /// ... and as the caller read it: the bound the pool is sized by before each scatter.
  void take_tiles_used(int32_t used);
  /// Bytes held now: tile index (host and device) plus the pool's capacity.
  size_t memory_bytes() const;
  /// Sum of density over all cells (in cell units), in double: kept up to date by every write
  /// (a scatter adds what it writes less what it overwrites), so it costs nothing whatever the
  /// size of the painting. A scatter's sums stay on the device until they are read (one host
  /// read, here or with a caller's own results: mass_sums / take_mass_sums).
  double total_density() const;
  /// The scatters' sums not yet read (two doubles on the device: written, overwritten) ...
  const double* mass_sums() const { return mass_sums_.data(); }
  /// ... and those sums as a caller read them: added to the total, and zeroed on the device.
  void take_mass_sums(const double sums[2]);
  /// The same sum counted over the whole tile pool (for tests of the running total).
  double recount_density(Workspace& ws) const;

  PaintCell read_cell(int x, int y, int z) const;
  /// Ids (ty * tiles_x + tx) of the allocated tiles, in slot order.
  std::vector<int> allocated_tile_ids() const;
  /// Whether tile `tile_id` is allocated (a lookup in the slot table).
  bool tile_allocated(int tile_id) const;
  TileData read_tile(int tile_id) const;
  /// read_tile into `d`, reusing its vectors' memory (a caller reading many tiles).
  void read_tile(int tile_id, TileData& d) const;
  /// Writes a whole tile (allocating it); sizes must be tile_cells().
  void write_tile(const TileData& data);

  TileStoreView view();

 private:
  int32_t ensure_slot(int tile_id);
  /// Brings the host's slot table up to the device's, where scatters allocated tiles (one read).
  void sync_host() const;
  void fold_mass_sums(const double sums[2]) const;  ///< the read sums into the total
  void grow_pool(int32_t slots);
  /// Drying the tile in `slot` is owed (clock less the clock its stored dryness includes).
  float owed_drying(int32_t slot) const { return float(clock_) - host_dried_to_[size_t(slot)]; }

  Device device_;
  CanvasDims dims_;
  int tiles_x_ = 0, tiles_y_ = 0;
  // The slot table: the device's is the truth (a scatter allocates there); the host's mirrors
  // it as of the last sync_host, and bound_ bounds the slots in use without a read.
  mutable std::vector<int32_t> host_slot_;  ///< mirror of slot_of_tile_
  mutable std::vector<int32_t> tile_of_slot_;
  mutable int32_t slots_used_ = 0;
  mutable bool host_stale_ = false;  ///< a scatter ran since the last sync_host
  mutable int64_t bound_ = 0;        ///< at least the slots in use
  mutable int64_t known_used_ = 0;   ///< the slots in use when the host last learnt it
  DeviceBuffer<int32_t> tile_of_slot_dev_, slots_used_dev_;
  int32_t slot_capacity_ = 0;
  DeviceBuffer<int32_t> slot_of_tile_;
  DeviceBuffer<float> density_;
  DeviceBuffer<uint16_t> pigment_r_, pigment_y_, pigment_b_, oil_, dryness_;
  DeviceBuffer<int32_t> tile_flags_;   ///< scratch of scatter: which window tiles hold paint
  double clock_ = 0.0;                 ///< drying clock
  mutable double mass_ = 0.0;          ///< sum of density over the pool, less mass_sums_
  mutable DeviceBuffer<double> mass_sums_;  ///< the scatters' written and overwritten sums since read
  mutable bool mass_pending_ = false;  ///< mass_sums_ may be non-zero
  Workspace ws_;                       ///< scratch of the scatter's mass difference
  DeviceBuffer<float> mass_before_, mass_after_;  ///< per window cell: density overwritten, written
  mutable std::vector<float> host_dried_to_;      ///< per slot, mirror of dried_to_ (sync_host)
  DeviceBuffer<float> dried_to_;
};

// The tile store's backend drivers (gather_scatter_impl.h), one list (core/exec/dispatch.h).
#define WB_TILE_STORE_KERNELS(X)                                                                               \
  X(void, tiles_gather_window, (TileStoreView t, PaintWindowView w), (t, w))                                   \
  X(void, tiles_settle_window, (TileStoreView t, int tx0, int ty0, int ntx, int nty), (t, tx0, ty0, ntx, nty)) \
  X(void, tiles_allocate_painted,                                                                              \
    (TileStoreView t, PaintWindowView w, int tx0, int ty0, int ntx, int nty, int32_t* flags, TileSlots slots), \
    (t, w, tx0, ty0, ntx, nty, flags, slots))                                                                  \
  X(void, tiles_scatter_window, (TileStoreView t, PaintWindowView w, float* before, float* after),             \
    (t, w, before, after))                                                                                     \
  X(void, tiles_dry_all, (TileStoreView t, int64_t cells), (t, cells))                                         \
  X(void, tiles_lay_weave, (TileStoreView t, WeaveField w, int64_t columns), (t, w, columns))
WB_DECLARE_KERNELS(WB_TILE_STORE_KERNELS)

}  // namespace wb
