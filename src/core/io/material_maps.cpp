#include "core/io/material_maps.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/io/png.h"
#include "core/render/renderer.h"

namespace wb {
namespace {

std::vector<uint8_t> to_rgb8(const FloatImage& f, bool signed_unit) {
  std::vector<uint8_t> out(size_t(f.width) * f.height * 3);
  for (size_t i = 0; i < out.size(); ++i) {
    const float v = signed_unit ? f.data[i] * 0.5f + 0.5f : f.data[i];
    out[i] = uint8_t(std::lround(std::fmin(std::fmax(v, 0.f), 1.f) * 255.f));
  }
  return out;
}

}  // namespace

double write_material_maps(const Device& device, TileStore& canvas, const MaterialMapPaths& paths) {
  Renderer r(device);
  const CanvasDims d = canvas.dims();
  const double scale = 65535.0 / d.depth;  // units per cell: the full range is the canvas depth
  if (!paths.height.empty()) {
    const FloatImage h = r.render_height_map(canvas);
    std::vector<uint16_t> q(h.data.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = uint16_t(std::lround(std::fmin(std::fmax(h.data[i] * scale, 0.0), 65535.0)));
    write_png_gray16(paths.height, q.data(), h.width, h.height,
                     {{"wetbrush:height_units_per_cell", std::to_string(scale)},
                      {"wetbrush:cell_size_mm", "0.2"},
                      {"wetbrush:canvas_depth_cells", std::to_string(d.depth)}});
  }
  if (!paths.normal.empty()) {
    FloatImage n = r.render_normal_map(canvas);
    for (size_t i = 1; i < n.data.size(); i += 3) n.data[i] = -n.data[i];  // canvas +y runs down the image
    write_png8(paths.normal, to_rgb8(n, true).data(), n.width, n.height, 3);
  }
  if (!paths.albedo.empty()) {
    const FloatImage a = r.render_albedo(canvas);
    write_png8(paths.albedo, to_rgb8(a, false).data(), a.width, a.height, 3);
  }
  return scale;
}

}  // namespace wb
