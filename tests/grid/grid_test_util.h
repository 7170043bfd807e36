// Scene helpers of the grid tests: paint written straight into the window, a moving
// solid plate rasterised as bristle density psi with its velocity.
#pragma once
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "core/grid/grid.h"

namespace wb::test {

using Fields = std::vector<std::vector<float>>;

inline Fields empty_fields(const Grid& g) {
  const GridDims d = const_cast<Grid&>(g).dims();
  return Fields(kPaintFieldCount, std::vector<float>(size_t(d.cells()), 0.f));
}

/// Paint given by fn(i, j, k) -> density, with fixed colour, oil and dryness.
inline void paint_cells(Grid& g, const std::function<float(int, int, int)>& density, float oil = 0.2f,
                        float dryness = 0.f) {
  const GridDims d = g.dims();
  Fields f = empty_fields(g);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const size_t c = size_t(d.cell(i, j, k));
        const float rho = density(i, j, k);
        f[0][c] = rho;
        if (rho > 0) {
          f[1][c] = 0.7f;
          f[2][c] = 0.2f;
          f[3][c] = 0.1f;
          f[4][c] = oil;
          f[5][c] = dryness;
        }
      }
  g.window().paint().from_host(f);
}

/// Host mirrors of a rasterised solid plate: psi = covered fraction of each cell.
struct HostBristles {
  DeviceBuffer<float> psi, vx, vy, vz;
  HostBristles(const Device& d, int64_t n) : psi(d, size_t(n)), vx(d, size_t(n)), vy(d, size_t(n)), vz(d, size_t(n)) {}
  BristleField field() { return BristleField{psi.data(), vx.data(), vy.data(), vz.data()}; }
  /// Plate covering x in [x0, x1) (fractional), y in [y0, y1), z in [0, z1), velocity (vx, 0, 0).
  void plate(const GridDims& d, float x0, float x1, int y0, int y1, int z1, float speed) {
    std::vector<float> p(size_t(d.cells()), 0.f), u(size_t(d.cells()), 0.f), zero(size_t(d.cells()), 0.f);
    for (int k = 0; k < std::min(z1, d.nz); ++k)
      for (int j = std::max(y0, 0); j < std::min(y1, d.ny); ++j)
        for (int i = 0; i < d.nx; ++i) {
          const float cover = std::max(0.f, std::min(float(i + 1), x1) - std::max(float(i), x0));
          if (cover <= 0.f) continue;
          p[size_t(d.cell(i, j, k))] = cover;
          u[size_t(d.cell(i, j, k))] = speed;
        }
    psi.copy_from_host(p);
    vx.copy_from_host(u);
    vy.copy_from_host(zero);
    vz.copy_from_host(zero);
  }
};

inline std::vector<float> host_density(Grid& g) { return g.window().paint().density.to_host(); }

inline double sum(const std::vector<float>& v) {
  double s = 0;
  for (float x : v) s += x;
  return s;
}

/// Centroid of a cell-centred field (window cells).
inline Vec3 centroid(const GridDims& d, const std::vector<float>& rho) {
  double m = 0, x = 0, y = 0, z = 0;
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const double r = rho[size_t(d.cell(i, j, k))];
        m += r;
        x += r * (i + 0.5);
        y += r * (j + 0.5);
        z += r * (k + 0.5);
      }
  return Vec3(float(x / m), float(y / m), float(z / m));
}

}  // namespace wb::test
