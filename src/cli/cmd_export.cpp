// `wetbrush export`: material maps of a painting for 3D tools (DESIGN "Files"): a 16-bit
// height map in cells, a tangent-space normal map and the unlit colour, one pixel per cell.
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "core/io/document.h"
#include "core/io/material_maps.h"

namespace wb::cli {

namespace {
struct ExportOpts {
  std::string painting, height, normal, albedo, device = "auto";
};
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
    const double scale = write_material_maps(device, p.canvas, MaterialMapPaths{o->height, o->normal, o->albedo});
    if (!o->height.empty())
      std::printf("wrote %s (height = value / %.4f cells; 1 cell = 0.2 mm)\n", o->height.c_str(), scale);
    for (const std::string* f : {&o->normal, &o->albedo})
      if (!f->empty()) std::printf("wrote %s\n", f->c_str());
    return 0;
  });
}

}  // namespace wb::cli
