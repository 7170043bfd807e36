// `wetbrush export`: what a painting becomes outside wetbrush (DESIGN "Files", docs/FORMATS.md):
// material maps for 3D tools (a 16-bit height map in cells, a tangent-space normal map and the
// unlit colour, one pixel per cell) and reliefs (the height in mm as OpenEXR, an STL solid, a
// textured glTF mesh).
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "core/session/session.h"
#if WB_WITH_MEDIA
#include "media/relief_export.h"
#endif

namespace wb::cli {

namespace {
struct ExportOpts {
  std::string painting, height, normal, albedo, device = "auto";
  std::string exr, stl, glb;
#if WB_WITH_MEDIA
  ReliefOptions relief;
#endif
};
}  // namespace

void register_export(CLI::App& app) {
  auto o = std::make_shared<ExportOpts>();
  CLI::App* sub = app.add_subcommand("export", "Export maps and reliefs of a painting (PNG, OpenEXR, STL, glTF)");
  sub->add_option("painting", o->painting, "Painting file (.ora)")->required();
  sub->add_option("--height", o->height,
                  "16-bit grey PNG: surface height, value = height / canvas depth * 65535 (scale in its tEXt)");
  sub->add_option("--normal", o->normal, "RGB PNG: tangent-space normal map, OpenGL convention (+Y up the image)");
  sub->add_option("--albedo", o->albedo, "RGB PNG: unlit paint colour");
#if WB_WITH_MEDIA  // the reliefs (src/media; not in a -DWB_MEDIA=OFF build)
  sub->add_option("--height-exr", o->exr, "OpenEXR: surface height in millimetres, 32-bit float channel Y");
  sub->add_option("--stl", o->stl, "Binary STL: closed solid of the paint on a base, millimetres, z up");
  sub->add_option("--gltf", o->glb, "glTF 2.0 binary (.glb): textured paint surface, metres, y up");
  sub->add_option("--base-mm", o->relief.base_mm, "STL: thickness of the base under the paint, mm")
      ->capture_default_str();
  sub->add_option("--error-mm", o->relief.error_mm,
                  "STL and glTF: most the decimated surface may differ from the height map, mm")
      ->capture_default_str();
#endif
  add_device_option(sub, o->device);
  set_action(sub, [o]() {
    if (o->height.empty() && o->normal.empty() && o->albedo.empty() && o->exr.empty() && o->stl.empty() &&
        o->glb.empty())
      WB_THROW("export: nothing to do: give --height, --normal, --albedo, --height-exr, --stl and/or --gltf");
#if WB_WITH_MEDIA
    WB_REQUIRE(o->relief.base_mm > 0.0 && o->relief.base_mm <= 1000.0, "export: --base-mm must be in (0, 1000]");
    WB_REQUIRE(o->relief.error_mm >= 0.0 && o->relief.error_mm <= 100.0, "export: --error-mm must be in [0, 100]");
#endif
    SimConfig base;
    base.device = resolve_device(o->device);
    const std::unique_ptr<Session> session = Session::open(o->painting, base);
    if (!o->height.empty() || !o->normal.empty() || !o->albedo.empty()) {
      const double scale = session->export_maps(MaterialMapPaths{o->height, o->normal, o->albedo});
      if (!o->height.empty())
        std::printf("wrote %s (height = value / %.4f cells; 1 cell = 0.2 mm)\n", o->height.c_str(), scale);
      for (const std::string* f : {&o->normal, &o->albedo})
        if (!f->empty()) std::printf("wrote %s\n", f->c_str());
    }
#if WB_WITH_MEDIA
    const ReliefStats s = write_relief_exports(*session, ReliefPaths{o->exr, o->stl, o->glb}, o->relief);
    if (!o->exr.empty()) std::printf("wrote %s (height in mm, float)\n", o->exr.c_str());
    if (!o->stl.empty())
      std::printf("wrote %s (%zu triangles, %.1f mm3 with a %.2f mm base)\n", o->stl.c_str(), s.stl.triangles,
                  s.stl.volume_mm3, o->relief.base_mm);
    if (!o->glb.empty())
      std::printf("wrote %s (%zu vertices of %d in the full grid, %zu triangles, within %.3f mm)\n", o->glb.c_str(),
                  s.glb.vertices, s.glb.grid_vertices, s.glb.triangles, o->relief.error_mm);
#endif
    return 0;
  });
}

}  // namespace wb::cli
