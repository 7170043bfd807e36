// The sparse canvas: empty cost, gather/scatter round trips at any position,
// windows over the canvas edges, unallocated tiles, memory growing with paint, drying by the
// canvas clock and undo snapshots that keep it.
#include <random>

#include "backend_fixture.h"
#include "core/exec/memory.h"
#include "core/canvas/tile_store.h"
#include "core/io/undo_tiles.h"

namespace wb::test {

class TileStoreTest : public BackendTest {
 protected:
  // Random paint in a window: each value already on the unorm16 lattice so that a
  // round trip must be bit-exact.
  std::vector<std::vector<float>> random_fields(int64_t n, unsigned seed, float fill = 0.5f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<std::vector<float>> f(kPaintFieldCount, std::vector<float>(size_t(n), 0.f));
    for (int64_t i = 0; i < n; ++i) {
      if (u(rng) > fill) continue;
      f[0][i] = u(rng) * 1.5f;
      for (int k = 1; k < kPaintFieldCount; ++k) f[k][i] = decode_unorm16(encode_unorm16(u(rng)));
    }
    return f;
  }
  /// A 256^2 x 16 canvas with random paint over a window at `origin` of `size`.
  TileStore painted(unsigned seed, Int3 origin = {30, 40, 0}, Int3 size = {100, 60, 16}) {
    TileStore c(device_, CanvasDims{256, 256, 16});
    PaintWindow w(device_, size);
    w.set_origin(origin);
    w.from_host(random_fields(w.cell_count(), seed));
    c.scatter(w);
    return c;
  }
  /// The same tiles, total and cells.
  void expect_same_canvas(TileStore& a, TileStore& b) {
    EXPECT_EQ(a.allocated_tiles(), b.allocated_tiles());
    EXPECT_DOUBLE_EQ(a.total_density(), b.total_density());
    PaintWindow wa(device_, Int3{256, 256, 16}), wb(device_, Int3{256, 256, 16});
    a.gather(wa);
    b.gather(wb);
    EXPECT_EQ(wa.to_host(), wb.to_host());
  }
};

TEST_F(TileStoreTest, EmptyDefaultCanvasIsSmall) {
  TileStore canvas(device_, CanvasDims{});
  EXPECT_EQ(canvas.allocated_tiles(), 0);
  EXPECT_LT(canvas.memory_bytes(), size_t(64) << 20);
  EXPECT_EQ(canvas.total_density(), 0.0);
}

TEST_F(TileStoreTest, GatherFromEmptyIsZero) {
  TileStore canvas(device_, CanvasDims{512, 512, 64});
  PaintWindow w(device_, Int3{64, 64, 32});
  w.set_origin({100, 37, 0});
  auto f = random_fields(w.cell_count(), 1, 1.f);
  w.from_host(f);
  canvas.gather(w);
  for (auto& field : w.to_host())
    for (float v : field) ASSERT_EQ(v, 0.f);
}

TEST_F(TileStoreTest, ScatterGatherRoundTripIsExact) {
  // A canvas whose last tiles it covers in part (509 = 31 tiles and 13 columns): the CPU takes a
  // row's cells a tile at a time.
  TileStore canvas(device_, CanvasDims{509, 383, 48});
  PaintWindow w(device_, Int3{40, 56, 20});
  for (Int3 origin : {Int3{0, 0, 0}, Int3{123, 77, 5}, Int3{497, 370, 30}, Int3{-20, -33, -4}}) {
    canvas.clear();
    w.set_origin(origin);
    auto f = random_fields(w.cell_count(), unsigned(origin.x + 1000));
    w.from_host(f);
    canvas.scatter(w);
    PaintWindow back(device_, w.dims());
    back.set_origin(origin);
    canvas.gather(back);
    auto g = back.to_host();
    const Int3 n = w.dims();
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          const int cx = x + origin.x, cy = y + origin.y, cz = z + origin.z;
          const bool inside = cx >= 0 && cy >= 0 && cz >= 0 && cx < 509 && cy < 383 && cz < 48;
          const size_t i = (size_t(z) * n.y + y) * n.x + x;
          for (int k = 0; k < kPaintFieldCount; ++k) {
            // Fields without paint are not kept in unallocated tiles: compare where paint is.
            const float expect = inside && f[0][i] != 0.f ? f[k][i] : 0.f;
            ASSERT_EQ(g[k][i], expect) << "field " << k << " at " << cx << "," << cy << "," << cz;
          }
        }
  }
}

TEST_F(TileStoreTest, MovingWindowKeepsMassExactly) {
  TileStore canvas(device_, CanvasDims{1024, 1024, 32});
  PaintWindow w(device_, Int3{64, 64, 32});
  w.set_origin({300, 300, 0});
  w.from_host(random_fields(w.cell_count(), 7, 0.3f));
  const double m0 = w.total_density(ws_);
  canvas.scatter(w);
  EXPECT_DOUBLE_EQ(canvas.total_density(), m0);
  // Walk the window around, overlapping its old place, across the edge and back.
  std::mt19937 rng(11);
  for (int step = 0; step < 40; ++step) {
    const Int3 o{int(rng() % 1100) - 40, int(rng() % 1100) - 40, 0};
    w.set_origin(o);
    canvas.gather(w);
    canvas.scatter(w);
  }
  EXPECT_NEAR(canvas.total_density(), m0, 1e-12 * m0);
  EXPECT_NEAR(canvas.recount_density(ws_), m0, 1e-12 * m0);
}

TEST_F(TileStoreTest, RunningMassIsThePoolsSumAfterAnyWrites) {
  // New paint scattered at random places (some across the edge, where it is dropped), tiles
  // written and overwritten, the canvas cleared: the running total always equals a recount.
  TileStore canvas(device_, CanvasDims{512, 512, 16});
  PaintWindow w(device_, Int3{48, 48, 16});
  std::mt19937 rng(3);
  for (int step = 0; step < 30; ++step) {
    w.set_origin(Int3{int(rng() % 560) - 40, int(rng() % 560) - 40, 0});
    w.from_host(random_fields(w.cell_count(), 100 + unsigned(step), 0.2f));
    canvas.scatter(w);
    if (step % 7 == 3) {
      TileData t = canvas.read_tile(int(rng() % 64));
      for (float& d : t.density) d = d > 0.f ? 0.5f * d : 0.25f;
      canvas.write_tile(t);
    }
    const double recount = canvas.recount_density(ws_);
    ASSERT_NEAR(canvas.total_density(), recount, 1e-9 * std::max(recount, 1.0)) << "after write " << step;
  }
  EXPECT_GT(canvas.total_density(), 0.0);
  canvas.clear();
  EXPECT_EQ(canvas.total_density(), 0.0);
}

TEST_F(TileStoreTest, MemoryGrowsWithPaintedArea) {
  TileStore canvas(device_, CanvasDims{});
  PaintWindow w(device_, Int3{32, 32, 8});
  const size_t empty = canvas.memory_bytes();
  std::vector<std::vector<float>> f(kPaintFieldCount, std::vector<float>(size_t(w.cell_count()), 0.f));
  f[0][0] = 1.f;  // one painted cell allocates exactly one tile
  w.from_host(f);
  w.set_origin({16 * 5, 16 * 9, 0});
  canvas.scatter(w);
  EXPECT_EQ(canvas.allocated_tiles(), 1);
  EXPECT_GT(canvas.memory_bytes(), empty);
  EXPECT_FLOAT_EQ(canvas.read_cell(80, 144, 0).density, 1.f);
  EXPECT_EQ(canvas.read_cell(81, 144, 0).density, 0.f);
}

TEST_F(TileStoreTest, ScatterAllocatesOnTheDeviceAndItsPoolStaysBounded) {
  // A scatter allocates the tiles its paint needs on the device and reads nothing back; the
  // host learns the count when it asks (one read). Scatters with no step record between them
  // (here: a window moving over bare canvas with one painted cell) keep the pool within a few
  // windows' tiles, not a window more at every move.
  TileStore canvas(device_, CanvasDims{1024, 256, 8});
  PaintWindow w(device_, Int3{64, 64, 8});
  std::vector<std::vector<float>> f(kPaintFieldCount, std::vector<float>(size_t(w.cell_count()), 0.f));
  f[0][size_t(w.cell_count()) - 1] = 1.f;  // the window's top far corner
  w.from_host(f);
  const int64_t reads = mem::host_reads();
  for (int m = 0; m < 40; ++m) {
    w.set_origin({16 * m, 64, 0});
    canvas.scatter(w);
  }
  const int64_t scatter_reads = mem::host_reads() - reads;
  // Each placement paints the cell at (16 m + 63, 127, 7): a tile per move from x 63 on.
  EXPECT_EQ(canvas.allocated_tiles(), 40);
  const int window_tiles = 5 * 5;  // 64 cells over 16-cell tiles, one more where not aligned
  const size_t tile_bytes = size_t(16 * 16 * 8) * size_t(kCellBytes);
  EXPECT_LT(canvas.memory_bytes(), size_t(40 + 4 * window_tiles) * 3 / 2 * tile_bytes + (1u << 20))
      << "the pool grew by a window at every move";
  // The table is read (its count, new slots and clocks: 3 reads) once the bound is two windows
  // past what the host knows: every third move here, where a step's record would do it each step.
  EXPECT_LE(scatter_reads, 3 * (40 / 3 + 1));
  EXPECT_FLOAT_EQ(canvas.read_cell(16 * 39 + 63, 127, 7).density, 1.f);
  std::printf("[ tiles ] 40 scatters: %lld host reads, %d tiles, pool %.1f MiB\n",
              static_cast<long long>(scatter_reads), canvas.allocated_tiles(),
              double(canvas.memory_bytes()) / 1048576.0);
}

TEST_F(TileStoreTest, DryAllSolidifiesPaintOnly) {
  TileStore canvas(device_, CanvasDims{64, 64, 16});
  PaintWindow w(device_, Int3{64, 64, 16});
  auto f = random_fields(w.cell_count(), 5, 0.5f);
  w.from_host(f);
  canvas.scatter(w);
  canvas.dry_all();
  canvas.gather(w);
  auto g = w.to_host();
  for (size_t i = 0; i < g[0].size(); ++i) EXPECT_EQ(g[5][i], g[0][i] > 0.f ? 1.f : 0.f);
}

TEST_F(TileStoreTest, TileReadWriteRoundTrip) {
  TileStore a = painted(9), b(device_, CanvasDims{256, 256, 16});
  for (int id : a.allocated_tile_ids()) b.write_tile(a.read_tile(id));
  expect_same_canvas(a, b);
  EXPECT_THROW(b.write_tile(TileData{}), Error);
}

TEST_F(TileStoreTest, CopyOnTheDeviceIsExactAndReadsNothingBack) {
  TileStore a = painted(11), b = painted(12, {200, 200, 0}, {40, 40, 16});  // b's paint is replaced
  a.advance_drying(0.25);  // owed drying travels with the copy
  const int64_t reads = mem::host_reads();
  b.copy_from(a);
  EXPECT_EQ(mem::host_reads(), reads) << "the canvas is not read back to the host";
  EXPECT_EQ(a.allocated_tile_ids(), b.allocated_tile_ids());
  EXPECT_EQ(a.drying_clock(), b.drying_clock());
  expect_same_canvas(a, b);
  EXPECT_THROW(b.copy_from(TileStore(device_, CanvasDims{128, 256, 16})), Error);
}

TEST_F(TileStoreTest, PaintDriesByTheClockAndUndoKeepsTheDrying) {
  TileStore canvas(device_, CanvasDims{64, 64, 8});
  TileData t = canvas.read_tile(0);
  t.density[0] = 1.f;       // paint
  t.dryness[1] = 1000;      // no paint: a stale dryness on an empty cell stays as it is
  canvas.write_tile(t);
  canvas.advance_drying(0.25);
  EXPECT_NEAR(canvas.read_cell(0, 0, 0).dryness, 0.25f, 1e-4f);
  EXPECT_EQ(canvas.read_tile(0).dryness[1], 1000);
  const TileSnapshot snap = snapshot_tile(canvas, 0);
  canvas.advance_drying(0.5);
  canvas.advance_drying(0.5);  // past full: dryness stops at 1
  EXPECT_EQ(canvas.read_cell(0, 0, 0).dryness, 1.f);
  // Undo writes the old paint back with the drying it has had since the snapshot.
  canvas.write_tile(t);  // the paint made wet again, as a stroke over it would
  restore_tile(canvas, snap);
  EXPECT_EQ(canvas.read_cell(0, 0, 0).dryness, 1.f);
  canvas.advance_drying(0.1);
  EXPECT_EQ(canvas.read_cell(0, 0, 0).dryness, 1.f);
  EXPECT_THROW(canvas.advance_drying(-1.0), Error);
}

}  // namespace wb::test
