// Analytic paint volumes for the renderer (tests, docs images, timings).
#include "core/render/test_volumes.h"

#include <algorithm>
#include <cmath>

#include "core/exec/error.h"

namespace wb {

float sdf_density(float sd, float width) { return std::clamp(0.5f + sd / width, 0.f, 1.f); }

void fill_volume(TileStore& canvas, int x0, int y0, int x1, int y1,
                 const std::function<PaintCell(int, int, int)>& fn) {
  const CanvasDims d = canvas.dims();
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, d.width);
  y1 = std::min(y1, d.height);
  const size_t n = size_t(canvas.tile_cells());
  const int tx0 = x0 / kTileSize, ty0 = y0 / kTileSize;
  const int ntx = std::max(0, (x1 + kTileSize - 1) / kTileSize - tx0), nty = std::max(0, (y1 + kTileSize - 1) / kTileSize - ty0);
  // Tiles are filled in parallel; the store itself is touched by one thread at a time.
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < ntx * nty; ++k) {
    {
      const int tx = tx0 + k % ntx, ty = ty0 + k / ntx;
      TileData t;
#pragma omp critical(wb_fill_volume)
      t = canvas.read_tile(ty * canvas.tiles_x() + tx);
      bool any = false;
      for (int z = 0; z < d.depth; ++z)
        for (int ly = 0; ly < kTileSize; ++ly)
          for (int lx = 0; lx < kTileSize; ++lx) {
            const int x = tx * kTileSize + lx, y = ty * kTileSize + ly;
            if (x < x0 || y < y0 || x >= x1 || y >= y1) continue;
            const PaintCell c = fn(x, y, z);
            if (!(c.density > 0.f)) continue;
            const size_t i = (size_t(z) * kTileSize + ly) * kTileSize + lx;
            t.density[i] = c.density;
            t.pigment_r[i] = encode_unorm16(c.pigment_r);
            t.pigment_y[i] = encode_unorm16(c.pigment_y);
            t.pigment_b[i] = encode_unorm16(c.pigment_b);
            t.oil[i] = encode_unorm16(c.oil);
            t.dryness[i] = encode_unorm16(c.dryness);
            any = true;
          }
      if (any && t.density.size() == n) {
#pragma omp critical(wb_fill_volume)
        canvas.write_tile(t);
      }
    }
  }
}

namespace {
PaintCell paint(float density, float r, float y, float b, float oil, float dryness = 0.f) {
  PaintCell c;
  c.density = density;
  c.pigment_r = r;
  c.pigment_y = y;
  c.pigment_b = b;
  c.oil = oil;
  c.dryness = dryness;
  return c;
}
// A cell of a height-field layer: density from the signed distance to z = h along z.
float layer_density(float h, int z) { return sdf_density(h - (float(z) + 0.5f)); }
}  // namespace

std::vector<std::string> test_volume_names() {
  return {"flat", "hemisphere", "ridges", "glaze", "swatches", "films", "impasto-1024"};
}

CanvasDims test_volume_dims(const std::string& name) {
  if (name == "flat") return {96, 96, 16};
  if (name == "hemisphere") return {96, 96, 32};
  if (name == "ridges") return {96, 96, 16};
  if (name == "glaze") return {128, 64, 16};
  if (name == "swatches") return {256, 128, 16};
  if (name == "films") return {192, 96, 16};
  if (name == "impasto-1024") return {1024, 1024, 32};
  WB_THROW("unknown test volume '" + name + "' (known: flat, hemisphere, ridges, glaze, swatches, films, impasto-1024)");
}

void make_test_volume(TileStore& canvas, const std::string& name) {
  const CanvasDims d = test_volume_dims(name);
  WB_REQUIRE(canvas.dims() == d, "make_test_volume: canvas size does not match test volume '" + name + "'");
  canvas.clear();
  if (name == "flat") {
    fill_volume(canvas, 16, 16, 80, 80, [](int, int, int z) { return paint(layer_density(4.f, z), 0.9f, 0.2f, 0.05f, 0.1f); });
  } else if (name == "hemisphere") {
    const float kRamp = 2.f;  // a surface smoothed over two cells, as grid advection leaves it
    fill_volume(canvas, 0, 0, d.width, d.height, [=](int x, int y, int z) {
      const float dx = x + 0.5f - 48.f, dy = y + 0.5f - 48.f, dz = z + 0.5f;
      return paint(sdf_density(24.f - std::sqrt(dx * dx + dy * dy + dz * dz), kRamp), 0.1f, 0.8f, 0.2f, 0.1f);
    });
  } else if (name == "ridges") {
    // Two parallel ridges along y, circular cross sections of radius 10 centred 16 cells apart
    // at z = 0, on a 2-cell base layer: a crease between them, flat tops elsewhere.
    fill_volume(canvas, 0, 0, d.width, d.height, [](int x, int y, int z) {
      const float xc = x + 0.5f, zc = z + 0.5f;
      const float d1 = 10.f - std::hypot(xc - 40.f, zc), d2 = 10.f - std::hypot(xc - 56.f, zc);
      const float base = 2.f - zc;
      return paint(sdf_density(std::max({d1, d2, base})), 0.15f, 0.15f, 0.7f, 0.1f);
    });
  } else if (name == "glaze") {
    // A 4-cell red layer; on the left a 1-cell oily blue glaze, on the right a 4-cell opaque one.
    fill_volume(canvas, 8, 8, 120, 56, [](int x, int, int z) {
      const bool left = x < 64;
      const float top = left ? 5.f : 8.f;
      const float dens = layer_density(top, z);
      if (float(z) + 0.5f < 4.f) return paint(dens, 1.f, 0.f, 0.f, 0.2f);
      return paint(dens, 0.f, 0.f, 1.f, left ? 1.f : 0.f);
    });
  } else if (name == "swatches") {
    // A row of colours (top) and a row of oil levels over a yellow stripe (bottom).
    const float cols[8][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {0.5f, 0.5f, 0.5f}, {0.1f, 0.1f, 0.1f}};
    fill_volume(canvas, 0, 0, d.width, d.height, [&](int x, int y, int z) {
      const int k = x / 32;
      const float cx = k * 32 + 16.f;
      if (y < 64) {
        const float h = 3.f + 2.5f * std::cos((x + 0.5f - cx) / 16.f * 1.5708f) * std::cos((y + 0.5f - 32.f) / 28.f * 1.5708f);
        if (std::fabs(x + 0.5f - cx) > 13.f || std::fabs(y + 0.5f - 32.f) > 26.f) return PaintCell{};
        return paint(layer_density(h, z), cols[k][0], cols[k][1], cols[k][2], 0.2f, k % 2 ? 1.f : 0.f);
      }
      // Bottom: a 2-cell yellow stripe under 2-cell red glazes of oil k/7.
      const float dens = layer_density(4.f, z);
      if (y < 72 || y >= 120) return PaintCell{};
      if (z < 2) return paint(dens, 0.f, 1.f, 0.f, 0.3f);
      return paint(dens, 1.f, 0.1f, 0.f, float(k) / 7.f);
    });
  } else if (name == "films") {
    // Top: squares of paint 0.01, 0.05, 0.1, 0.3, 0.6 and 2 cells thick (2 um to 0.4 mm).
    // Bottom: paint rising along x from none to a 3-cell layer (upper rows), and to two full
    // cells spread evenly over both, density 0 to 1 (lower rows).
    const float thick[6] = {0.01f, 0.05f, 0.1f, 0.3f, 0.6f, 2.f};
    fill_volume(canvas, 0, 0, d.width, d.height, [&](int x, int y, int z) {
      const float f = (float(x) - 8.f + 0.5f) / 176.f;
      float dens = 0.f;
      if (y >= 8 && y < 40 && (x - 8) % 30 < 24 && x >= 8 && x < 8 + 6 * 30) {
        dens = layer_density(thick[(x - 8) / 30], z);
      } else if (y >= 52 && y < 88 && x >= 8 && x < 184) {
        dens = y < 70 ? layer_density(3.f * f, z) : (z < 2 ? f : 0.f);
      }
      return paint(dens, 0.9f, 0.3f, 0.05f, 0.1f);
    });
  } else if (name == "impasto-1024") {
    // Thick strokes everywhere: a wavy height field 1..9 cells, a colour that changes by
    // region, a top layer of another colour, oil varying slowly. Every tile holds paint.
    fill_volume(canvas, 0, 0, d.width, d.height, [](int x, int y, int z) {
      const float fx = float(x), fy = float(y);
      const float h = 5.f + 2.5f * std::sin(fx / 17.f) * std::cos(fy / 23.f) + 1.5f * std::sin((fx + 2.f * fy) / 9.f);
      const float dens = layer_density(h, z);
      if (dens <= 0.f) return PaintCell{};
      const float u = 0.5f + 0.5f * std::sin(fx / 97.f + fy / 61.f), w = 0.5f + 0.5f * std::cos(fy / 83.f - fx / 140.f);
      const float oil = 0.5f + 0.5f * std::sin(fx / 200.f);
      if (float(z) + 0.5f < h - 1.5f) return paint(dens, u, 1.f - u, w * 0.5f, oil, 0.5f);
      return paint(dens, w, 0.3f * u, 1.f - w, oil, fy / 1024.f);
    });
  }
}

}  // namespace wb
