// `wetbrush render`: ray-cast a painting (or a built-in test volume) to a PNG (paper §6),
// with the camera, light and AO settings on the command line; --repeat and --incremental
// time a full render and an incremental window update.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "core/io/document.h"
#include "core/io/png.h"
#include "core/render/renderer.h"
#include "core/render/test_volumes.h"
#include "core/session/session.h"

namespace wb::cli {

namespace {
struct RenderOpts {
  std::string painting, out, camera = "top", light, center, size, test_volume, save, device = "auto";
  float zoom = 1.f, elevation = 40.f;
  int ao_rays = 64, repeat = 1, incremental = 0;
};

Vec3 parse_vec3(const std::string& s, const char* what) {
  Vec3 v;
  char c1 = 0, c2 = 0;
  std::istringstream in(s);
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',')
    WB_THROW(std::string(what) + ": expected three numbers x,y,z, got '" + s + "'");
  return v;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

void register_render(CLI::App& app) {
  auto o = std::make_shared<RenderOpts>();
  CLI::App* sub = app.add_subcommand("render", "Ray-cast a painting (.ora) to a PNG image");
  sub->add_option("painting", o->painting, "Painting file (.ora)");
  sub->add_option("-o,--output", o->out, "Output PNG");
  sub->add_option("--camera", o->camera, "top (one pixel per cell by default) or oblique")
      ->check(CLI::IsMember({"top", "oblique"}))
      ->capture_default_str();
  sub->add_option("--zoom", o->zoom, "Image pixels per canvas cell")->capture_default_str();
  sub->add_option("--center", o->center, "Top view: canvas point x,y at the image centre (cells)");
  sub->add_option("--size", o->size, "Top view: image size WxH in pixels (default: whole canvas)");
  sub->add_option("--elevation", o->elevation, "Oblique view: degrees above the horizon")->capture_default_str();
  sub->add_option("--light", o->light, "Direction towards the light x,y,z (z up)");
  sub->add_option("--ao-rays", o->ao_rays, "Ambient-occlusion rays per pixel (0 = off)")->capture_default_str();
  sub->add_option("--test-volume", o->test_volume,
                  "Render a built-in volume instead of a file: flat, hemisphere, ridges, glaze, swatches, films, impasto-1024");
  sub->add_option("--save", o->save, "Also save the rendered volume as a painting (.ora)");
  sub->add_option("--repeat", o->repeat, "Render this many times and print the median time")->capture_default_str();
  sub->add_option("--incremental", o->incremental,
                  "Also time an incremental update of an NxN window at the canvas centre (cache by tile)");
  add_device_option(sub, o->device);
  set_action(sub, [o]() {
    if (o->painting.empty() == o->test_volume.empty())
      WB_THROW("render: give either a painting file or --test-volume NAME");
    WB_REQUIRE(o->repeat >= 1 && o->repeat <= 1000, "render: --repeat must be in [1, 1000]");
    const Device device = resolve_device(o->device);
    std::unique_ptr<TileStore> canvas;
    if (!o->test_volume.empty()) {
      canvas = std::make_unique<TileStore>(device, test_volume_dims(o->test_volume));
      make_test_volume(*canvas, o->test_volume);
    } else {
      canvas = std::make_unique<TileStore>(std::move(load_painting(o->painting, device).canvas));
    }
    const CanvasDims dims = canvas->dims();
    Renderer renderer(device);
    RenderParams& p = renderer.params();
    p.ao_rays = o->ao_rays;
    if (!o->light.empty()) p.light_dir = parse_vec3(o->light, "--light");

    Camera cam;
    if (o->camera == "oblique") {
      cam = Camera::oblique(dims, o->elevation, o->zoom);
    } else {
      float w = float(dims.width), h = float(dims.height);
      if (!o->size.empty()) {
        int iw = 0, ih = 0;
        char x = 0;
        std::istringstream in(o->size);
        if (!(in >> iw >> x >> ih) || x != 'x' || iw <= 0 || ih <= 0) WB_THROW("--size: expected WxH, got '" + o->size + "'");
        w = iw / o->zoom;
        h = ih / o->zoom;
      } else {
        w = dims.width;
        h = dims.height;
      }
      float cx = dims.width * 0.5f, cy = dims.height * 0.5f;
      if (!o->center.empty()) {
        char c = 0;
        std::istringstream in(o->center);
        if (!(in >> cx >> c >> cy) || c != ',') WB_THROW("--center: expected x,y, got '" + o->center + "'");
      }
      cam = Camera::top_region(cx - w * 0.5f, cy - h * 0.5f, w, h, o->zoom);
    }

    // Wall time, and the process CPU time summed over threads (a fair measure on a busy machine).
    std::vector<double> times, cpu;
    Image img;
    for (int k = 0; k < o->repeat; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      img = renderer.render(*canvas, cam);
      times.push_back(ms_since(t0));
      cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
    }
    std::printf("render: %s %dx%d on %s: %.1f ms wall, %.1f ms CPU (medians of %d)\n", o->camera.c_str(), img.width,
                img.height, device.to_string().c_str(), median(times), median(cpu), o->repeat);
    if (o->incremental > 0) {
      // A simulation step changes only the window: paint there is rewritten (same values,
      // so the picture stays comparable) and the cache re-renders the affected tiles.
      CanvasImageCache cache(renderer, cam, 32);
      cache.update(*canvas);
      PaintWindow w(device, Int3{o->incremental, o->incremental, std::min(32, dims.depth)});
      w.set_origin({dims.width / 2 - o->incremental / 2, dims.height / 2 - o->incremental / 2, 0});
      std::vector<double> inc, inc_cpu;
      int tiles = 0;
      for (int k = 0; k < o->repeat; ++k) {
        canvas->gather(w);
        canvas->scatter(w);
        const auto t0 = std::chrono::steady_clock::now();  // the render's share of the step
        const std::clock_t c0 = std::clock();
        cache.mark_window_dirty(w);
        cache.update(*canvas, &w);
        inc.push_back(ms_since(t0));
        inc_cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
        tiles = cache.last_rendered_tiles();
      }
      std::printf("incremental: %dx%d window, %d of %d image tiles re-rendered: %.1f ms wall, %.1f ms CPU (medians of %d)\n",
                  o->incremental, o->incremental, tiles, ((cam.width + 31) / 32) * ((cam.height + 31) / 32),
                  median(inc), median(inc_cpu), o->repeat);
    }
    if (!o->out.empty()) {
      write_png8(o->out, img.rgba.data(), img.width, img.height, 4);
      std::printf("wrote %s\n", o->out.c_str());
    }
    if (!o->save.empty()) {
      // Saved as every painting is (Session::save), with the view's render parameters.
      SimConfig cfg;
      cfg.device = device;
      cfg.canvas = dims;
      cfg.window.z = std::min(cfg.window.z, dims.depth);
      cfg.params.render = p;
      Session session(cfg);
      session.load(*canvas);
      // The source file's name only: a painting records no path of the machine that made it.
      const std::string source =
          o->test_volume.empty() ? std::filesystem::path(o->painting).filename().string() : o->test_volume;
      session.save(o->save, {{"generator", "wetbrush render"}, {"source", source}});
      std::printf("wrote %s\n", o->save.c_str());
    }
    return 0;
  });
}

}  // namespace wb::cli
