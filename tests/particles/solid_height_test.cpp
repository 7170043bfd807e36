// The solid the particles rest on (Eq. 8's d_k): canvas floor plus dried paint, per column; and
// the wet paint's surface, which free particles land on.
#include <algorithm>
#include <vector>

#include "backend_fixture.h"
#include "core/canvas/window.h"
#include "core/particles/particles.h"

namespace wb::test {

class SolidHeightTest : public BackendTest {};

TEST_F(SolidHeightTest, DriedPaintRaisesTheFloorWetPaintDoesNot) {
  const Int3 n{8, 4, 6};
  PaintWindow w(device_, n);
  w.set_origin(Int3{100, 200, 0});
  std::vector<std::vector<float>> f(kPaintFieldCount, std::vector<float>(size_t(w.cell_count()), 0.f));
  auto at = [&](int i, int j, int k) { return (size_t(k) * n.y + j) * n.x + i; };
  for (int j = 0; j < n.y; ++j) {
    // Column 1: three dried cells, the top one half full. Column 2: two dried cells under two
    // wet ones. Column 3: wet paint only. Column 4: a dried cell above a gap.
    for (int k = 0; k < 3; ++k) f[0][at(1, j, k)] = k == 2 ? 0.5f : 1.f, f[5][at(1, j, k)] = 1.f;
    for (int k = 0; k < 4; ++k) f[0][at(2, j, k)] = 1.f, f[5][at(2, j, k)] = k < 2 ? 1.f : 0.2f;
    for (int k = 0; k < 3; ++k) f[0][at(3, j, k)] = 1.f, f[5][at(3, j, k)] = 0.1f;
    f[0][at(4, j, 4)] = 1.f, f[5][at(4, j, 4)] = 1.f;
  }
  w.from_host(f);
  // The dried paint's own top per column (column_solid_tops: the ground under the brush), in runs
  // of 5 columns, the last one shorter.
  PaintWindowView hv = w.view();
  hv.density = f[0].data();
  hv.dryness = f[5].data();
  std::vector<float> hh(size_t(n.x) * n.y);
  std::vector<int> above(hh.size());
  for (int64_t c = 0; c < int64_t(hh.size()); c += 5)
    column_solid_tops(hv, c, int(std::min<int64_t>(5, int64_t(hh.size()) - c)), 0.95f, 0.25f, &hh[size_t(c)],
                      &above[size_t(c)]);
  for (int j = 0; j < n.y; ++j) {
    EXPECT_FLOAT_EQ(hh[size_t(j) * n.x + 0], 0.25f) << "no paint: the canvas floor";
    EXPECT_FLOAT_EQ(hh[size_t(j) * n.x + 1], 2.5f) << "top of the dried layer, half-full top cell";
    EXPECT_FLOAT_EQ(hh[size_t(j) * n.x + 2], 2.f) << "wet paint on dried paint: the dried top";
    EXPECT_FLOAT_EQ(hh[size_t(j) * n.x + 3], 0.25f) << "wet paint is not solid";
    EXPECT_FLOAT_EQ(hh[size_t(j) * n.x + 4], 5.f) << "the highest dried cell counts";
  }
  // What the particles rest on: the grid's cells, one state each, so over the half-full dried
  // top cell of column 1 the floor and the wet paint start at that cell's top; elsewhere the
  // dried top. The wet paint's surface: the solid's where there is no wet paint on it.
  DeviceBuffer<float> hg(device_, size_t(n.x) * n.y), wg(device_, size_t(n.x) * n.y);
  particles_solid_height(device_, w.view(), nullptr, 0.95f, 0.5f, 0.25f, hg.data(), wg.data());
  const std::vector<float> hgh = hg.to_host(), wgh = wg.to_host();
  const float wet[5] = {0.25f, 3.f, 4.f, 3.f, 5.f};  // two wet cells on the dried ones; three on the canvas
  for (int j = 0; j < n.y; ++j)
    for (int i = 0; i < n.x; ++i) {
      const size_t c = size_t(j) * n.x + i;
      EXPECT_FLOAT_EQ(hgh[c], i == 1 ? 3.f : hh[c]) << "column " << i;
      EXPECT_FLOAT_EQ(wgh[c], i < 5 ? wet[i] : 0.25f) << "column " << i;
    }
  // A particle resting above column 1 is 0.5 cells from the solid; above column 3, 2.25.
  SolidView s;
  s.floor_z = 0.25f;
  std::vector<float> host = hh;
  s.height = host.data();
  s.nx = n.x, s.ny = n.y, s.ox = 100, s.oy = 200;
  EXPECT_FLOAT_EQ(solid_distance(s, Vec3(101.5f, 201.5f, 3.f)), 0.5f);
  EXPECT_FLOAT_EQ(solid_distance(s, Vec3(103.5f, 201.5f, 2.5f)), 2.25f);
}

}  // namespace wb::test
