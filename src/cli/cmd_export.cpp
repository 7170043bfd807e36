// `wetbrush export`: material maps of a painting for 3D tools (DESIGN "Files"): a 16-bit
// height map in cells, a tangent-space normal map and the unlit colour, one pixel per cell.
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "core/io/document.h"
#include "core/io/png.h"
#include "core/render/renderer.h"

namespace wb::cli {

namespace {
struct ExportOpts {
  std::string painting, height, normal, albedo, device = "auto";
};
std::vector<uint8_t> to_rgb8(const FloatImage& f, bool signed_unit) {
  std::vector<uint8_t> out(size_t(f.width) * f.height * 3);
  for (size_t i = 0; i < out.size(); ++i) {
    const float v = signed_unit ? f.data[i] * 0.5f + 0.5f : f.data[i];
    out[i] = uint8_t(std::lround(std::fmin(std::fmax(v, 0.f), 1.f) * 255.f));
  }
  return out;
}
}  // namespace

void register_export(CLI::App& app) {
  auto o = std::make_shared<ExportOpts>();
  CLI::App* sub = app.add_subcommand("export", "Export height, normal and colour maps of a painting");
  sub->add_option("painting", o->painting, "Painting file (.ora)")->required();
  sub->add_option("--height", o->height,
                  "16-bit grey PNG: surface height, value = height / canvas depth * 65535 (scale in its tEXt)");
  sub->add_option("--normal", o->normal, "RGB PNG: tangent-space normal map, OpenGL convention (+Y up the image)");
  sub->add_option("--albedo", o->albedo, "RGB PNG: unlit paint colour");
  add_device_option(sub, o->device);
  set_action(sub, [o]() {
    if (o->height.empty() && o->normal.empty() && o->albedo.empty())
      WB_THROW("export: nothing to do: give --height, --normal and/or --albedo");
    const Device device = resolve_device(o->device);
    Painting p = load_painting(o->painting, device);
    Renderer r(device);
    const CanvasDims d = p.canvas.dims();
    if (!o->height.empty()) {
      const FloatImage h = r.render_height_map(p.canvas);
      const double scale = 65535.0 / d.depth;  // units per cell: the full range is the canvas depth
      std::vector<uint16_t> q(h.data.size());
      for (size_t i = 0; i < q.size(); ++i) q[i] = uint16_t(std::lround(std::fmin(std::fmax(h.data[i] * scale, 0.0), 65535.0)));
      write_png_gray16(o->height, q.data(), h.width, h.height,
                       {{"wetbrush:height_units_per_cell", std::to_string(scale)},
                        {"wetbrush:cell_size_mm", "0.2"},
                        {"wetbrush:canvas_depth_cells", std::to_string(d.depth)}});
      std::printf("wrote %s (height = value / %.4f cells; 1 cell = 0.2 mm)\n", o->height.c_str(), scale);
    }
    if (!o->normal.empty()) {
      FloatImage n = r.render_normal_map(p.canvas);
      for (size_t i = 1; i < n.data.size(); i += 3) n.data[i] = -n.data[i];  // canvas +y runs down the image
      write_png8(o->normal, to_rgb8(n, true).data(), n.width, n.height, 3);
      std::printf("wrote %s\n", o->normal.c_str());
    }
    if (!o->albedo.empty()) {
      const FloatImage a = r.render_albedo(p.canvas);
      write_png8(o->albedo, to_rgb8(a, false).data(), a.width, a.height, 3);
      std::printf("wrote %s\n", o->albedo.c_str());
    }
    return 0;
  });
}

}  // namespace wb::cli
