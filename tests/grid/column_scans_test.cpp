// The passes down every column of the window in runs of columns (parallel_for_runs<kColumnLanes>) give
// what a column at a time gives: the tops of the paint and particles, the particles' floor and
// free surface, and their ground, on windows whose column count is no multiple of a run, with and
// without particles, over dried, wet and floating paint.
#include <cmath>
#include <random>
#include <vector>

#include "backend_fixture.h"
#include "core/canvas/paint_fields.h"
#include "core/canvas/window.h"
#include "core/grid/grid.h"
#include "core/grid/project_kernels.h"
#include "core/particles/particles.h"

namespace wb::test {
namespace {

struct Window {
  Int3 n;
  std::vector<std::vector<float>> f;  // the paint's fields (density 0, dryness 5)
  std::vector<float> particles;
  float density(int64_t c) const { return f[0][size_t(c)]; }
  float dryness(int64_t c) const { return f[5][size_t(c)]; }
};

/// Columns of dried paint at the bottom, wet paint over it, paint floating over a gap and
/// particles in some cells: every case a scan tells apart.
Window random_window(Int3 n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  Window w{n, std::vector<std::vector<float>>(kPaintFieldCount, std::vector<float>(size_t(n.x) * n.y * n.z, 0.f)),
           std::vector<float>(size_t(n.x) * n.y * n.z, 0.f)};
  const int64_t layer = int64_t(n.x) * n.y;
  for (int64_t c = 0; c < layer; ++c) {
    const int dried = int(u(rng) * 3.f), wet = int(u(rng) * 4.f);
    for (int k = 0; k < n.z; ++k) {
      const int64_t id = int64_t(k) * layer + c;
      if (k < dried) w.f[0][size_t(id)] = k + 1 == dried ? 0.3f + 0.7f * u(rng) : 1.f, w.f[5][size_t(id)] = 1.f;
      else if (k < dried + wet) w.f[0][size_t(id)] = k + 1 == dried + wet ? u(rng) : 1.f, w.f[5][size_t(id)] = 0.2f;
      else if (u(rng) < 0.05f) w.f[0][size_t(id)] = u(rng);  // floating, or a trace
      if (u(rng) < 0.1f) w.particles[size_t(id)] = u(rng);
    }
  }
  return w;
}

class ColumnScansTest : public BackendTest {};

TEST_F(ColumnScansTest, RunsOfColumnsGiveWhatAColumnAtATimeGives) {
  constexpr float kDry = 0.95f, kLiquid = 0.5f, kFloor = 0.25f;
  for (const Int3 n : {Int3{37, 23, 9}, Int3{16, 2, 5}, Int3{5, 3, 4}})
    for (const bool with_particles : {false, true}) {
      const Window h = random_window(n, uint32_t(n.x * 7 + with_particles));
      PaintWindow w(device_, n);
      w.set_origin(Int3{40, 60, 0});
      w.from_host(h.f);
      DeviceBuffer<float> pd(device_, h.particles.size());
      pd.copy_from_host(h.particles);
      const float* particles = with_particles ? pd.data() : nullptr;
      const int64_t layer = int64_t(n.x) * n.y;
      DeviceBuffer<float> tops(device_, size_t(6 * layer)), height(device_, size_t(layer)),
          wet_top(device_, size_t(layer)), ground(device_, size_t(layer));
      const GridDims d{n.x, n.y, n.z};
      grid_column_tops(device_, d, w.density.data(), w.dryness.data(), kDry, particles, kTraceDensity, tops.data());
      particles_solid_height(device_, w.view(), particles, kDry, kLiquid, kFloor, height.data(), wet_top.data());
      particles_ground_surface(device_, w.view(), particles, kDry, kLiquid, kFloor, ground.data());
      const std::vector<float> th = tops.to_host(), hh = height.to_host(), wh = wet_top.to_host(),
                               gh = ground.to_host();
      for (int64_t c = 0; c < layer; ++c) {
        // A column at a time, as the scans read before they took runs.
        const auto pdens = [&](int k) { return with_particles ? h.particles[size_t(k * layer + c)] : 0.f; };
        float top = 0.f, joint = 0.f;
        for (int k = n.z - 1; k >= 0; --k) {
          const float r = h.density(k * layer + c), dr = h.dryness(k * layer + c);
          const bool wet = r > kTraceDensity && (!(dr >= kDry) || !dried_solid(r, dr, kDry));
          if (wet && top == 0.f) top = float(k + 1);
          if ((wet || pdens(k) > kTraceDensity) && joint == 0.f) joint = float(k + 1);
        }
        int above = 0;
        float solid = kFloor;
        for (int k = n.z - 1; k >= 0; --k)
          if (dried_solid(h.density(k * layer + c), h.dryness(k * layer + c), kDry)) {
            above = k + 1, solid = std::fmax(kFloor, float(k) + std::fmin(h.density(k * layer + c), 1.f));
            break;
          }
        const float floor = above > 0 ? std::fmax(kFloor, float(above)) : solid;
        float surface = floor;
        for (int k = n.z - 1; k >= above; --k) {
          const float j = h.density(k * layer + c) + pdens(k);
          if (j >= kLiquid) {
            surface = std::fmax(floor, float(k) + std::fmin(j, 1.f));
            break;
          }
        }
        float g = solid;
        for (int k = above; k < n.z; ++k) {
          const float j = h.density(k * layer + c) + pdens(k);
          g = std::fmax(g, float(k) + std::fmin(j, 1.f));
          if (j < kLiquid) break;
        }
        const auto at = [&](int s) { return th[size_t(s * layer + c)]; };
        ASSERT_EQ(at(0), top) << "column " << c << " of " << n.x << "x" << n.y;
        ASSERT_EQ(at(1), joint) << "column " << c;
        ASSERT_EQ(at(2), joint > 0.f ? float(c % n.x) : -INFINITY) << "column " << c;
        ASSERT_EQ(at(5), joint > 0.f ? -float(c / n.x) : -INFINITY) << "column " << c;
        ASSERT_EQ(hh[size_t(c)], floor) << "column " << c;
        ASSERT_EQ(wh[size_t(c)], surface) << "column " << c;
        ASSERT_EQ(gh[size_t(c)], g) << "column " << c;
      }
    }
}

}  // namespace
}  // namespace wb::test
