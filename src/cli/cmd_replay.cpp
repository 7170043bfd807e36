// `wetbrush replay STROKES`: runs a stroke file (JSON or MyPaint dump) through the
// simulator headless, writes the image, optional frames and a stats JSON.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "core/io/png.h"
#include "core/io/stroke.h"
#include "core/sim/replay.h"

namespace wb::cli {
namespace {

struct ReplayArgs {
  std::string strokes;
  std::string image;
  std::string stats;
  std::string frames_dir;
  int every = 10;
  std::string device = "auto";
  std::string brush_shape;
  bool quiet = false;
};

double median_of_differences(const std::vector<double>& a, const std::vector<double>& b) {
  // Per-step differences (a includes b as a nested scope), then the median.
  std::vector<double> d;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) d.push_back(a[i] - b[i]);
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) WB_THROW("cannot write '" + path + "'");
  f << text;
  if (!f.flush()) WB_THROW("failed writing '" + path + "'");
}

int run_replay(const ReplayArgs& a) {
  const Device device = resolve_device(a.device);
  Stroke stroke = load_stroke(a.strokes);
  if (!a.brush_shape.empty()) {
    const BrushSpec old = stroke.brush;
    stroke.brush = default_brush(brush_shape_from_string(a.brush_shape));
    stroke.brush.seed = old.seed;
  }
  for (const std::string& w : stroke.warnings) std::fprintf(stderr, "wetbrush: warning: %s\n", w.c_str());
  if (!a.frames_dir.empty()) {
    WB_REQUIRE(a.every > 0, "--every must be at least 1");
    std::filesystem::create_directories(a.frames_dir);
  }

  StrokePlayer player(stroke);
  SimConfig cfg;
  cfg.device = device;
  cfg.canvas = stroke.canvas;
  cfg.brush = stroke.brush;
  Simulator sim(cfg, player.pose_at(player.t_begin()));
  Replay replay(sim, player);

  const bool progress = !a.quiet && isatty(STDERR_FILENO);
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  double last_print = -1.0;
  while (replay.advance()) {
    const int64_t done = replay.steps_done();
    if (!a.frames_dir.empty() && done % a.every == 0) {
      char name[64];
      std::snprintf(name, sizeof name, "/frame_%06lld.png", static_cast<long long>(done));
      const auto img = replay.brush_image();
      write_png8(a.frames_dir + name, img.data(), replay.region().width, replay.region().height, 3);
    }
    if (progress && (elapsed() - last_print > 0.25 || done == replay.step_count())) {
      last_print = elapsed();
      const double rate = done / std::max(1e-9, elapsed());
      const double eta = (replay.step_count() - done) / std::max(1e-9, rate);
      std::fprintf(stderr, "\rstep %lld/%lld  %.2f s simulated  %.1f steps/s  ETA %.0f s   ",
                   static_cast<long long>(done), static_cast<long long>(replay.step_count()), replay.sim_time(), rate,
                   eta);
    }
  }
  if (progress) std::fprintf(stderr, "\n");
  const double wall_ms = elapsed() * 1e3;

  if (!a.image.empty()) {
    const auto img = replay.brush_image();
    write_png8(a.image, img.data(), replay.region().width, replay.region().height, 3);
  }

  const Profiler& prof = sim.profiler();
  const int64_t nonfinite = sim.counters().nonfinite_events;
  if (!a.stats.empty()) {
    nlohmann::json j;
    j["steps"] = replay.steps_done();
    j["substeps"] = sim.counters().steps;
    j["device"] = device.to_string();
    j["wall_ms"] = wall_ms;
    j["sim_time_s"] = replay.sim_time();
    j["stroke"] = a.strokes;
    j["region"] = {{"x0", replay.region().x0}, {"y0", replay.region().y0}, {"width", replay.region().width},
                   {"height", replay.region().height}};
    j["brush"] = {{"shape", to_string(stroke.brush.shape)},
                  {"bristles", stroke.brush.bristles},
                  {"vertices_per_bristle", stroke.brush.vertices_per_bristle},
                  {"samples_per_bristle", stroke.brush.samples_per_bristle},
                  {"max_stretch", replay.max_stretch()},
                  {"contact_cells_max", replay.contact_cells_max()}};
    j["timing_ms"] = {
        {"brush", median_of_differences(prof.samples("brush.step"), prof.samples("brush.samples"))},
        {"samples", prof.median_ms("brush.samples")},
        {"step_median", prof.median_ms("sim.step")}};
    j["nonfinite_events"] = nonfinite;
    j["warnings"] = stroke.warnings;
    write_text_file(a.stats, j.dump(2) + "\n");
  }
  if (!a.quiet)
    std::printf("replayed %lld steps (%.2f s of stroke) on %s in %.0f ms%s\n",
                static_cast<long long>(replay.steps_done()), replay.sim_time(), device.to_string().c_str(), wall_ms,
                nonfinite ? " (non-finite steps contained)" : "");
  return nonfinite ? 3 : 0;
}

}  // namespace

void register_replay(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  CLI::App* sub = app.add_subcommand("replay", "Replay a stroke file (JSON or MyPaint dump) headless");
  sub->add_option("STROKES", args->strokes, "Stroke file: wetbrush JSON or MyPaint 't x y pressure' dump")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("-o,--output", args->image, "Write the final image (PNG)");
  sub->add_option("--stats", args->stats, "Write replay statistics (JSON)");
  sub->add_option("--frames", args->frames_dir, "Write a PNG frame every --every steps into this folder");
  sub->add_option("--every", args->every, "Frame interval in steps")->capture_default_str();
  sub->add_option("--brush", args->brush_shape,
                  "Replace the stroke's brush by the default brush of this shape "
                  "(round, flat, fan, filbert, angular, mop, rigger)");
  sub->add_flag("-q,--quiet", args->quiet, "No progress or summary output");
  add_device_option(sub, args->device);
  set_action(sub, [args]() { return run_replay(*args); });
}

}  // namespace wb::cli
