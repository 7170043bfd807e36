// Advection (semi-Lagrangian, Stam 1999) and the active window (§4.2 last paragraph):
// a blob lands where a uniform field takes it, velocity sampling is exact on linear
// fields, window moves never change the total mass and carry the velocity with them.
#include <cmath>
#include <random>

#include "backend_fixture.h"
#include "core/grid/advect_kernels.h"
#include "grid/grid_test_util.h"

namespace wb::test {

class AdvectWindowTest : public BackendTest {};

TEST_F(AdvectWindowTest, SmoothBlobLandsWithinHalfACell) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  Grid g(canvas, GridParams{}, Int3{48, 48, 24}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  const Vec3 start(14.f, 16.f, 8.f), vel(30.f, 15.f, 12.f);
  paint_cells(g, [&](int i, int j, int k) {
    const float dx = i + 0.5f - start.x, dy = j + 0.5f - start.y, dz = k + 0.5f - start.z;
    return std::exp(-(dx * dx + dy * dy + dz * dz) / (2.f * 2.5f * 2.5f));
  });
  const auto rho0 = host_density(g);
  const Vec3 c0 = centroid(d, rho0);
  const float dt = g.params().dt;
  const int steps = 30;
  for (int s = 0; s < steps; ++s) {
    for (int c = 0; c < 3; ++c) {
      std::vector<float> v(size_t(d.faces(c)), vel[c]);
      g.window().velocity(c).copy_from_host(v);
    }
    g.classify();
    g.advect(dt);
  }
  const auto rho1 = host_density(g);
  const Vec3 c1 = centroid(d, rho1);
  const Vec3 expect = c0 + vel * (dt * steps);
  EXPECT_NEAR(c1.x, expect.x, 0.5f);
  EXPECT_NEAR(c1.y, expect.y, 0.5f);
  EXPECT_NEAR(c1.z, expect.z, 0.5f);
  float peak0 = 0, peak1 = 0;
  for (float x : rho0) peak0 = std::max(peak0, x);
  for (float x : rho1) peak1 = std::max(peak1, x);
  EXPECT_LE(peak1, peak0 * 1.0001f);  // trilinear sampling is bounded
  EXPECT_NEAR(sum(rho1), sum(rho0), 1e-4 * sum(rho0));  // with the mass correction
}

TEST_F(AdvectWindowTest, VelocitySamplingIsExactOnLinearFields) {
  const GridDims d{12, 10, 8};
  std::vector<float> f[3];
  auto field = [](int c, Vec3 p) { return c == 0 ? 1.f + 2.f * p.x - p.y : (c == 1 ? 0.5f * p.z + p.x : -3.f + p.y); };
  for (int c = 0; c < 3; ++c) {
    f[c].resize(size_t(d.faces(c)));
    int ex, ey, ez;
    d.face_extent(c, ex, ey, ez);
    for (int k = 0; k < ez; ++k)
      for (int j = 0; j < ey; ++j)
        for (int i = 0; i < ex; ++i) f[c][size_t(d.fidx(c, i, j, k))] = field(c, face_position(c, i, j, k));
  }
  GridView v{};
  v.d = d;
  for (int c = 0; c < 3; ++c) v.vel[c] = f[c].data();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(1.f, 7.f);
  for (int t = 0; t < 100; ++t) {
    const Vec3 p(u(rng), u(rng), u(rng) * 0.9f);
    const Vec3 s = sample_velocity(v, p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[c], field(c, p), 1e-4f);
  }
}

TEST_F(AdvectWindowTest, WindowMovesNeverChangeTotalMass) {
  TileStore canvas(device_, CanvasDims{300, 260, 64});
  ActiveWindow w(canvas, Int3{64, 48, 32}, Int3{100, 100, 0});
  // Paint the canvas through the window at a few places.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (Int3 o : {Int3{100, 100, 0}, Int3{10, 30, 0}, Int3{200, 190, 0}, Int3{150, 40, 0}}) {
    w.move_to(o);
    auto f = w.paint().to_host();
    for (size_t c = 0; c < f[0].size(); ++c)
      if (u(rng) < 0.3f) f[0][c] += u(rng) * 1.3f;
    w.paint().from_host(f);
  }
  Workspace ws(device_);
  const double total0 = w.total_mass(ws);
  ASSERT_GT(total0, 1000.0);
  std::uniform_int_distribution<int> ox(-70, 290), oy(-60, 250);
  for (int m = 0; m < 40; ++m) {
    Int3 o{ox(rng), oy(rng), 0};
    if (m % 3 == 0) o = Int3{w.origin().x + 8, w.origin().y - 8, 0};  // small overlapping moves
    w.move_to(o);
    EXPECT_NEAR(w.total_mass(ws), total0, 1e-6 * total0) << "move " << m;
  }
  w.flush();
  EXPECT_NEAR(canvas.total_density(), total0, 1e-6 * total0);
}

TEST_F(AdvectWindowTest, MovesCarryVelocityWithTheCanvas) {
  TileStore canvas(device_, CanvasDims{512, 512, 64});
  ActiveWindow w(canvas, Int3{32, 24, 16}, Int3{100, 100, 0});
  const GridDims d = w.grid_dims();
  // Each component as a function of the canvas position of each face, laid before each move;
  // after it, a face holds the value of its canvas position where the old window had that
  // face, and 0 elsewhere. Moves along every axis and sign, and one past the window.
  auto value = [](int c, int cx, int cy, int cz) {
    return 1.f + float(cx) + 1000.f * float(cy) + 0.25f * float(cz) + 1e6f * float(c);
  };
  const Int3 moves[] = {{8, -8, 0}, {-5, 3, 0}, {0, 7, 0}, {-9, 0, 0}, {3, -2, 1}, {1, 1, -1}, {40, 0, 0}};
  for (const Int3& m : moves) {
    const Int3 o = w.origin(), to{o.x + m.x, o.y + m.y, o.z + m.z};
    for (int c = 0; c < 3; ++c) {
      int ex, ey, ez;
      d.face_extent(c, ex, ey, ez);
      std::vector<float> v(size_t(d.faces(c)));
      for (int k = 0; k < ez; ++k)
        for (int j = 0; j < ey; ++j)
          for (int i = 0; i < ex; ++i) v[size_t((int64_t(k) * ey + j) * ex + i)] = value(c, i + o.x, j + o.y, k + o.z);
      w.velocity(c).copy_from_host(v);
    }
    w.move_to(to);
    for (int c = 0; c < 3; ++c) {
      int ex, ey, ez;
      d.face_extent(c, ex, ey, ez);
      const auto v = w.velocity(c).to_host();
      for (int k = 0; k < ez; ++k)
        for (int j = 0; j < ey; ++j)
          for (int i = 0; i < ex; ++i) {
            const int si = i + m.x, sj = j + m.y, sk = k + m.z;
            const bool overlap = si >= 0 && sj >= 0 && sk >= 0 && si < ex && sj < ey && sk < ez;
            const float expect = overlap ? value(c, i + to.x, j + to.y, k + to.z) : 0.f;
            ASSERT_EQ(v[size_t((int64_t(k) * ey + j) * ex + i)], expect)
                << "move " << m.x << "," << m.y << "," << m.z << " component " << c << " face " << i << " " << j << " "
                << k;
          }
    }
  }
}

TEST_F(AdvectWindowTest, RecentreSnapsToTheGrid) {
  TileStore canvas(device_, CanvasDims{1024, 1024, 64});
  ActiveWindow w(canvas, Int3{128, 128, 32}, Int3{0, 0, 0});
  EXPECT_TRUE(w.recentre_on(Vec3(500.f, 300.f, 0.f), 8));
  EXPECT_EQ(w.origin().x % 8, 0);
  EXPECT_EQ(w.origin().y % 8, 0);
  EXPECT_LE(std::abs(w.origin().x + 64 - 500), 4);
  EXPECT_LE(std::abs(w.origin().y + 64 - 300), 4);
  EXPECT_FALSE(w.recentre_on(Vec3(502.f, 301.f, 0.f), 8));  // less than the snap: no gather/scatter
}

// The paint's advection visits only the tiles of columns within its reach of the paint
// (docs/GRID.md "Work in proportion to the paint"). The same paint and velocity in a window whose
// sides are not multiples of the tile, and in a larger window holding it at an offset that puts
// the tiles elsewhere, advect to the same cells bit for bit: at 10 cells a step (11 sub-steps,
// a reach of two tiles) the paint crosses tiles, rises over its top and leaves columns empty.
// The flow runs away from the small window's low walls and its traces (one cell a pass) stop
// short of the high ones, so the walls, where the two windows differ, see no paint.
TEST_F(AdvectWindowTest, TiledAdvectionEqualsAnyTilingOfTheSameCells) {
  const Int3 small{141, 45, 14}, large{160, 56, 14};
  const int ox = 5, oy = 3;  // the small window's cell (0, 0) in the large one
  auto paint_at = [](int i, int j, int k) {  // small-window cells
    const bool blob = i >= 10 && i < 18 && j >= 8 && j < 16 && k < 6;
    return blob ? (k == 5 ? 0.4f : 1.f) : 0.f;
  };
  // p in small-window cells; across y only in the first two steps (4 steps carry the paint past
  // tiles it left, whose scratch cells keep what the passes wrote there).
  auto velocity_at = [](int c, Vec3 p, int step) {
    return c == 0 ? 600.f
                  : (c == 1 ? (step < 2 ? 40.f * (1.f + std::sin(p.x / 7.f)) : 0.f)
                            : (p.z > 0.5f ? 15.f * (1.f + std::cos(p.y / 5.f)) : 0.f));
  };
  std::vector<std::vector<float>> result[2];
  float courant = 0.f;
  for (int w = 0; w < 2; ++w) {
    TileStore canvas(device_, CanvasDims{256, 256, 64});
    const Int3 dims = w == 0 ? small : large;
    const int sx = w == 0 ? 0 : ox, sy = w == 0 ? 0 : oy;
    Grid g(canvas, GridParams{}, dims, Int3{32, 32, 0});
    const GridDims d = g.dims();
    paint_cells(g, [&](int i, int j, int k) { return paint_at(i - sx, j - sy, k); });
    for (int s = 0; s < 4; ++s) {
      for (int c = 0; c < 3; ++c) {
        std::vector<float> v(size_t(d.faces(c)));
        int ex, ey, ez;
        d.face_extent(c, ex, ey, ez);
        for (int k = 0; k < ez; ++k)
          for (int j = 0; j < ey; ++j)
            for (int i = 0; i < ex; ++i)
              v[size_t(d.fidx(c, i, j, k))] = velocity_at(c, face_position(c, i, j, k) - Vec3(float(sx), float(sy), 0.f), s);
        g.window().velocity(c).copy_from_host(v);
      }
      g.classify();
      g.advect(g.params().dt);
      g.read_record();
      courant = std::max(courant, g.stats().advect_courant);
    }
    // Back to small-window cells.
    const auto f = g.window().paint().to_host();
    result[w].assign(size_t(kPaintFieldCount), std::vector<float>(size_t(small.x) * small.y * small.z, 0.f));
    for (int q = 0; q < kPaintFieldCount; ++q)
      for (int k = 0; k < small.z; ++k)
        for (int j = 0; j < small.y; ++j)
          for (int i = 0; i < small.x; ++i)
            result[w][size_t(q)][(size_t(k) * small.y + size_t(j)) * small.x + size_t(i)] =
                f[size_t(q)][size_t(d.cell(i + sx, j + sy, k))];
    if (w == 1) {
      // Nothing outside the small window's cells.
      double outside = 0;
      for (int k = 0; k < d.nz; ++k)
        for (int j = 0; j < d.ny; ++j)
          for (int i = 0; i < d.nx; ++i)
            if (i < sx || j < sy || i >= sx + small.x || j >= sy + small.y) outside += f[0][size_t(d.cell(i, j, k))];
      EXPECT_EQ(outside, 0.0);
    }
  }
  std::printf("[ tiles ] the paint carried up to %.1f cells a step\n", courant);
  EXPECT_GE(courant, 9.f) << "the reach must span more than one tile";
  double moved = 0;
  for (int k = 0; k < small.z; ++k)
    for (int j = 0; j < small.y; ++j)
      for (int i = 0; i < small.x; ++i)
        if (i >= 40) moved += result[0][0][(size_t(k) * small.y + size_t(j)) * small.x + size_t(i)];
  EXPECT_GT(moved, 100.0) << "the blob must have crossed tiles";
  // And risen: the upflow lifts it (passes skip the layers above the paint's top plus one).
  int top = 0;
  for (int k = 0; k < small.z; ++k)
    for (int j = 0; j < small.y; ++j)
      for (int i = 0; i < small.x; ++i)
        if (result[0][0][(size_t(k) * small.y + size_t(j)) * small.x + size_t(i)] > 1e-6f) top = std::max(top, k + 1);
  std::printf("[ tiles ] paint above 1e-6 up to layer %d (from 6)\n", top);
  EXPECT_GE(top, 8) << "the paint must have risen";
  for (int q = 0; q < kPaintFieldCount; ++q) EXPECT_EQ(result[0][size_t(q)], result[1][size_t(q)]) << "field " << q;
}

}  // namespace wb::test
