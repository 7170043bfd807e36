// `wetbrush replay STROKES`: runs a stroke file (JSON or MyPaint dump) through the
// simulator headless; writes the rendered painting, optional frames, the brush trace,
// an OpenRaster painting and a stats JSON (docs/FORMATS.md, "Replay statistics").
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/progress.h"
#include "core/exec/memory.h"
#include "core/io/atomic_file.h"
#include "core/io/document.h"
#include "core/io/png.h"
#include "core/io/stroke.h"
#if WB_WITH_MEDIA
#include "media/timelapse.h"
#endif
#include "core/params/param_table.h"
#include "core/render/renderer.h"
#include "core/session/session.h"

namespace wb::cli {
namespace {

struct ReplayArgs {
  std::string strokes;
  std::string image;
  std::string brush_image;
  std::string save;
  std::string stats;
  std::string frames_dir;
  int every = 10;
  std::string device = "auto";
  std::string brush_shape;
  std::vector<float> color;
  float oil = -1.f;
  float load = -1.f;
  bool no_reload = false;
  bool grid_only = false;
  std::vector<int> window;
  std::vector<std::string> sets;
  std::string params_file;
  bool quiet = false;
  double progress_every = 10.0;  ///< seconds between progress lines written to a log
  bool bench = false;  ///< `wetbrush bench`: no pictures; a per-stage timing table
  std::string bench_json;
  std::string video;  ///< time-lapse MP4
  int fps = 30;
  double speed = 4.0;  ///< simulated seconds per second of video
  std::string video_camera = "top";
};

double median_of_differences(const std::vector<double>& a, const std::vector<double>& b) {
  // Per-step differences (a includes b as a nested scope), then the median.
  std::vector<double> d;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) d.push_back(a[i] - b[i]);
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

/// Applies the command-line overrides of the stroke's brush and paint (MyPaint dumps carry neither).
void apply_overrides(const ReplayArgs& a, Stroke& stroke) {
  if (!a.brush_shape.empty()) {
    const uint32_t seed = stroke.brush.seed;
    stroke.brush = default_brush(brush_shape_from_string(a.brush_shape));
    stroke.brush.seed = seed;
  }
  if (!a.color.empty()) {
    WB_REQUIRE(a.color.size() == 3, "--color takes three RYB components, e.g. --color 0.1,0.8,0.1");
    for (int i = 0; i < 3; ++i) {
      WB_REQUIRE(std::isfinite(a.color[i]) && a.color[i] >= 0.f && a.color[i] <= 1.f,
                 "--color components must be in [0, 1]");
      stroke.paint.ryb[i] = a.color[i];
    }
  }
  if (a.oil >= 0.f) {
    WB_REQUIRE(a.oil <= 1.f, "--oil must be in [0, 1]");
    stroke.paint.oil = a.oil;
  }
  if (a.load >= 0.f) {
    WB_REQUIRE(a.load <= 1.f, "--load must be in [0, 1]");
    stroke.paint.load = a.load;
  }
  if (a.no_reload) stroke.paint.reload_on_pen_down = false;
}

/// `wetbrush bench`: every profiler scope's median, 90th percentile and share of the step
/// (the paper's Figure 12), the step rate against the stroke's own clock, and memory.
/// Per step of a bench run: the viscous solve's CG iterations and the residual it reached,
/// and the paint advection's sub-steps.
struct SolveLog {
  std::vector<double> iterations, residual, courant, passes;
};

void report_bench(const ReplayArgs& a, const Simulator& sim, const Stroke& stroke, const Device& device,
                  int64_t steps, const SolveLog& solve) {
  const Profiler& prof = sim.profiler();
  const double step_ms = prof.median_ms("sim.step");
  auto pct = [](std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
  };
  const mem::Usage use = mem::usage(!device.is_cpu());
  nlohmann::json stages = nlohmann::json::object();
  std::printf("%s on %s: %lld steps, %lld particles at most\n", a.strokes.c_str(), device.to_string().c_str(),
              static_cast<long long>(steps), static_cast<long long>(sim.counters().particles_max));
  // Host reads per call of a scope, the mean over its calls (each read waits for the GPU).
  auto mean_reads = [&](const std::string& name) {
    const std::vector<int64_t>& r = prof.host_reads(name);
    double s = 0;
    for (int64_t x : r) s += double(x);
    return r.empty() ? 0.0 : s / double(r.size());
  };
  auto mean_launches = [&](const std::string& name) {
    const std::vector<int64_t>& r = prof.launches(name);
    double s = 0;
    for (int64_t x : r) s += double(x);
    return r.empty() ? 0.0 : s / double(r.size());
  };
  std::printf("%-28s %10s %10s %10s %7s %6s %8s %9s\n", "stage", "median ms", "p90 ms", "worst ms", "calls", "step%",
              "reads", "launches");
  for (const std::string& name : prof.names()) {
    const std::vector<double>& v = prof.samples(name);
    const double med = prof.median_ms(name), p90 = pct(v, 0.9), worst = pct(v, 1.0);
    std::printf("%-28s %10.3f %10.3f %10.3f %7zu %5.1f%% %8.1f %9.1f\n", name.c_str(), med, p90, worst, v.size(),
                step_ms > 0 ? 100.0 * med / step_ms : 0.0, mean_reads(name), mean_launches(name));
    stages[name] = {{"median_ms", med},
                    {"p90_ms", p90},
                    {"max_ms", worst},
                    {"calls", v.size()},
                    {"host_reads_mean", mean_reads(name)},
                    {"launches_mean", mean_launches(name)}};
  }
  const double waits = mean_reads("sim.step:whole"), launches = mean_launches("sim.step:whole");
  // The step's rate is that of the steps timed whole (sim.step:whole): as a painter's step runs.
  const double whole_ms = prof.count("sim.step:whole") ? prof.median_ms("sim.step:whole") : step_ms;
  const double rate = whole_ms > 0 ? 1e3 / whole_ms : 0.0;
  std::printf("step rate %.1f steps/s, %.2f x real time (dt %.4g s); %s memory %.1f MiB peak, %.1f MiB held\n",
              rate, rate * stroke.dt, stroke.dt, device.is_cpu() ? "host" : "device",
              double(use.peak) / 1048576.0, double(use.in_use) / 1048576.0);
  const double it_med = pct(solve.iterations, 0.5), it_max = pct(solve.iterations, 1.0);
  const double res_med = pct(solve.residual, 0.5), res_max = pct(solve.residual, 1.0);
  std::printf("viscous solve: %.0f CG iterations median, %.0f most; residual %.2e median, %.2e worst (tolerance %.0e)\n",
              it_med, it_max, res_med, res_max, double(sim.config().params.grid.viscosity_tolerance));
  std::printf("paint advection: %.0f one-axis passes median; outflow Courant number %.2f median, %.2f most\n",
              pct(solve.passes, 0.5), pct(solve.courant, 0.5), pct(solve.courant, 1.0));
  // The tail a painter feels: the whole step's 90th percentile and worst, and the mean, whose
  // inverse against the stroke's clock is the replay's real-time factor over the whole stroke.
  const std::vector<double>& whole = prof.samples(prof.count("sim.step:whole") ? "sim.step:whole" : "sim.step");
  double whole_sum = 0.0;
  for (double x : whole) whole_sum += x;
  const double whole_mean = whole.empty() ? 0.0 : whole_sum / double(whole.size());
  const double whole_p90 = pct(whole, 0.9), whole_max = pct(whole, 1.0);
  std::printf("step timed whole: %.3f ms median, %.3f p90, %.3f worst, %.3f mean (%.2f x real time overall; "
              "stages timed: %.3f ms median)\n",
              whole_ms, whole_p90, whole_max, whole_mean, whole_mean > 0 ? 1e3 * stroke.dt / whole_mean : 0.0,
              step_ms);
  std::printf("host waits: %.1f a step (mean; reads of device results, column `reads`); launches: %.0f a step\n",
              waits, launches);
  if (!a.bench_json.empty()) {
    nlohmann::json j{{"stroke", a.strokes},
                     {"device", device.to_string()},
                     {"steps", steps},
                     {"particles_max", sim.counters().particles_max},
                     {"step_rate", rate},
                     {"real_time_factor", rate * stroke.dt},
                     {"host_waits_per_step", waits},
                     {"launches_per_step", launches},
                     {"step_median_ms", whole_ms},
                     {"step_p90_ms", whole_p90},
                     {"step_max_ms", whole_max},
                     {"step_mean_ms", whole_mean},
                     {"memory_peak_bytes", use.peak},
                     {"viscous_solve",
                      {{"iterations_median", it_med},
                       {"iterations_max", it_max},
                       {"residual_median", res_med},
                       {"residual_max", res_max}}},
                     {"advection_courant", {{"median", pct(solve.courant, 0.5)}, {"max", pct(solve.courant, 1.0)}}},
                     {"advection_passes", {{"median", pct(solve.passes, 0.5)}, {"max", pct(solve.passes, 1.0)}}},
                     {"stages", stages}};
    write_file_atomic(a.bench_json, j.dump(2) + "\n");
  }
}

/// The simulator's configuration for a stroke and the command's options.
SimConfig replay_config(const ReplayArgs& a, const Stroke& stroke, const Device& device) {
  SimConfig cfg = stroke_config(stroke, device);
  cfg.particles = !a.grid_only;
  if (!a.window.empty()) {
    WB_REQUIRE(a.window.size() == 3 && a.window[0] >= 16 && a.window[1] >= 16 && a.window[2] >= 8 &&
                   a.window[0] <= 1024 && a.window[1] <= 1024 && a.window[2] <= 256,
               "--window takes X,Y,Z cells (16..1024, 16..1024, 8..256)");
    cfg.window = Int3{a.window[0], a.window[1], std::min(a.window[2], stroke.canvas.depth)};
  }
  // The stroke's tilt and paper are set; a parameter file or --set overrides them.
  if (!a.params_file.empty()) {
    std::ifstream f(a.params_file);
    WB_REQUIRE(f.good(), "cannot read parameter file '" + a.params_file + "'");
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(f);
    } catch (const nlohmann::json::exception& e) {
      WB_THROW(a.params_file + ": " + e.what());
    }
    std::vector<std::string> warnings;
    params_from_json(cfg.params, j, warnings);
    for (const auto& w : warnings) std::fprintf(stderr, "wetbrush: warning: %s: %s\n", a.params_file.c_str(), w.c_str());
  }
  for (const std::string& s : a.sets) apply_param_assignment(cfg.params, s);
  return cfg;
}

/// The stroke with the window, tilt and paper its configuration resolved: Session::begin_replay
/// applies a stroke's own, which would undo --window, --set and --params.
void configure_stroke(Stroke& stroke, const SimConfig& cfg) {
  stroke.window = std::array<int, 3>{cfg.window.x, cfg.window.y, cfg.window.z};
  stroke.tilt = cfg.params.grid.tilt;
  const Vec3 paper = cfg.params.render.paper_rgb;
  stroke.paper_rgb = std::array<float, 3>{paper.x, paper.y, paper.z};
}

int run_replay(const ReplayArgs& a) {
  const Device device = resolve_device(a.device);
  Stroke stroke = load_stroke(a.strokes);
  apply_overrides(a, stroke);
  for (const std::string& w : stroke.warnings) std::fprintf(stderr, "wetbrush: warning: %s\n", w.c_str());
  if (!a.frames_dir.empty()) {
    WB_REQUIRE(a.every > 0, "--every must be at least 1");
    std::filesystem::create_directories(a.frames_dir);
  }
  const SimConfig cfg = replay_config(a, stroke, device);
  configure_stroke(stroke, cfg);

  Session session(cfg, start_pose(stroke));
  session.begin_replay(stroke);
  const Simulator& sim = session.sim();
  const Replay& replay = *session.replay();
  const CanvasRect& r = replay.region();
  const Camera camera = Camera::top_region(float(r.x0), float(r.y0), float(r.width), float(r.height), 1.f);

  // The time-lapse (media/timelapse.h): frame 0 now, the frames due after each step, the
  // settled painting last.
#if WB_WITH_MEDIA
  std::unique_ptr<TimelapseRecorder> video;
  if (!a.video.empty()) {
    video = std::make_unique<TimelapseRecorder>(a.video, r, stroke.canvas.depth,
                                                TimelapseOptions{a.fps, a.speed, a.video_camera == "oblique"});
    if (!video->video().fallback_note().empty())
      std::fprintf(stderr, "wetbrush: warning: %s\n", video->video().fallback_note().c_str());
    video->begin(session);
  }
#endif

  Progress progress(!a.quiet, a.progress_every);
  const auto elapsed = [&] { return progress.elapsed(); };
  mem::reset_peak();
  SolveLog solve;
  // The bench times every other step whole, its stages untimed: on CUDA the stages' scopes wait
  // for the device at their ends, which lengthens the step they break up (profile.h).
  Profiler& profiler = session.sim().profiler();
  if (a.bench) profiler.set_outermost(true);
  while (session.advance()) {
    const int64_t done = replay.steps_done();
    if (a.bench) profiler.set_outermost(!profiler.outermost());
    if (a.bench) {
      solve.iterations.push_back(sim.grid().stats().viscosity_iterations);
      solve.residual.push_back(sim.grid().stats().viscosity_residual);
      solve.courant.push_back(sim.grid().stats().advect_courant);
      solve.passes.push_back(sim.grid().stats().advect_passes);
    }
    if (!a.frames_dir.empty() && done % a.every == 0) {
      char name[64];
      std::snprintf(name, sizeof name, "/frame_%06lld.png", static_cast<long long>(done));
      const Image img = session.render(camera);
      write_png8(a.frames_dir + name, img.rgba.data(), img.width, img.height, 4);
    }
    char detail[128];
    std::snprintf(detail, sizeof detail, "%.2f s simulated  %lld particles", replay.sim_time(),
                  static_cast<long long>(sim.particles().size()));
#if WB_WITH_MEDIA
    if (video) {
      video->after_step(session, replay.sim_time());
      std::snprintf(detail, sizeof detail, "%.2f s simulated  %lld particles  %lld video frames", replay.sim_time(),
                    static_cast<long long>(sim.particles().size()), static_cast<long long>(video->video().frames()));
    }
#endif
    progress.step(done, replay.step_count(), "", detail, done == replay.step_count());
  }
  progress.finish();
  const double wall_ms = elapsed() * 1e3;
  if (a.bench) {
    report_bench(a, sim, stroke, device, replay.steps_done(), solve);
    return sim.counters().nonfinite_events ? 3 : 0;
  }
  const int64_t particles_final = sim.particles().size();

  // The stroke is over: particles settle into the grid and the canvas holds the painting.
  session.settle();
  double render_ms = 0.0;
  Image painting;
  if (!a.image.empty() || !a.save.empty()) {
    const auto tr = std::chrono::steady_clock::now();
    painting = session.render(camera);
    render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tr).count();
  }
  if (!a.image.empty()) write_png8(a.image, painting.rgba.data(), painting.width, painting.height, 4);
#if WB_WITH_MEDIA
  if (video) {
    // The top view's last frame is the image -o writes, when it was rendered.
    const bool same = video->camera().kind == CameraKind::Top && !painting.rgba.empty();
    video->finish(session, same ? &painting : nullptr);
    const VideoWriter& v = video->video();
    if (!a.quiet)
      std::printf("wrote %s: %lld frames at %d fps (%.2f s), %dx%d, %s\n", a.video.c_str(),
                  static_cast<long long>(v.frames()), a.fps, double(v.frames()) / a.fps, v.encoded_width(),
                  v.encoded_height(), v.encoder().c_str());
  }
#endif
  if (!a.brush_image.empty()) {
    const auto img = replay.brush_image();
    write_png8(a.brush_image, img.data(), r.width, r.height, 3);
  }
  if (!a.save.empty())
    // The stroke file's name only: a painting records no path of the machine that made it.
    session.save(a.save, {{"generator", "wetbrush replay"},
                          {"stroke", std::filesystem::path(a.strokes).filename().string()}});

  const Profiler& prof = sim.profiler();
  const PaintBooks& books = sim.books();
  const PaintCensus census = books.steps().empty() ? PaintCensus{} : books.steps().back().census;
  const int64_t nonfinite = sim.counters().nonfinite_events;
  const double drift = books.max_drift();
  if (!a.stats.empty()) {
    nlohmann::json j;
    j["steps"] = replay.steps_done();
    j["substeps"] = sim.counters().substeps;
    j["device"] = device.to_string();
    j["wall_ms"] = wall_ms;
    j["sim_time_s"] = replay.sim_time();
    j["stroke"] = a.strokes;
    j["mode"] = cfg.particles ? "hybrid" : "grid-only";
    const Int3 w = sim.config().window;  // the window and tilt the session ran
    j["window"] = {w.x, w.y, w.z};
    j["tilt_deg"] = sim.config().params.grid.tilt;
    j["region"] = {{"x0", r.x0}, {"y0", r.y0}, {"width", r.width}, {"height", r.height}};
    j["brush"] = {{"shape", to_string(stroke.brush.shape)},
                  {"bristles", stroke.brush.bristles},
                  {"vertices_per_bristle", stroke.brush.vertices_per_bristle},
                  {"samples_per_bristle", stroke.brush.samples_per_bristle},
                  {"max_stretch", replay.max_stretch()},
                  {"contact_cells_max", replay.contact_cells_max()}};
    j["paint"] = {{"mass_initial", books.initial_total()},
                  {"mass_loaded", books.external_total()},
                  {"mass_final", census.total()},
                  {"mass_drift", drift},
                  {"bristles", census.bristles},
                  {"particles", census.particles},
                  {"grid", census.grid}};
    j["particles"] = {{"max", sim.counters().particles_max},
                      {"final", particles_final},
                      {"limit", sim.particle_limit()},
                      {"refused", sim.counters().particles_refused}};
    const TransferTotals& t = books.totals();
    j["transfer"] = {{"absorbed", t.absorbed},         {"emitted", t.emitted},
                     {"to_particles", t.to_particles}, {"to_grid", t.to_grid},
                     {"absorbed_count", t.absorbed_count}, {"emitted_count", t.emitted_count},
                     {"to_particles_count", t.to_particles_count}, {"to_grid_count", t.to_grid_count},
                     {"max_closure_error", t.max_closure_error}};
    j["timing_ms"] = {
        {"brush", median_of_differences(prof.samples("brush.step"), prof.samples("brush.samples"))},
        {"samples", prof.median_ms("brush.samples")},
        {"window", prof.median_ms("window")},
        {"particles", prof.median_ms("particles")},
        {"grid", prof.median_ms("grid")},
        {"flip", prof.median_ms("particles.flip")},
        {"transfer", prof.median_ms("transfer")},
        {"books", prof.median_ms("books")},
        {"render", render_ms},
        {"step_median", prof.median_ms("sim.step")}};
    j["nonfinite_events"] = nonfinite;
    j["zone_cut_steps"] = sim.counters().zone_cut_steps;
    j["box_reads"] = sim.counters().box_reads;
    j["split_steps"] = sim.counters().split_steps;
    j["step_parts"] = sim.counters().step_parts;
    j["warnings"] = stroke.warnings;
    write_file_atomic(a.stats, j.dump(2) + "\n");
  }
  if (sim.counters().zone_cut_steps > 0) {
    const Int3 w = sim.config().window;
    const int need = int(std::ceil(-sim.counters().zone_room_min)) * 2;
    std::fprintf(stderr,
                 "wetbrush: warning: on %lld of %lld steps the brush and its particle zone did not fit the %dx%d "
                 "window (bands across the stroke at the window's snap may follow); a window about %dx%d holds them "
                 "(simulation.window or --window)\n",
                 static_cast<long long>(sim.counters().zone_cut_steps), static_cast<long long>(sim.counters().steps),
                 w.x, w.y, w.x + need, w.y + need);
  }
  if (!a.quiet)
    std::printf("replayed %lld steps (%.2f s of stroke) on %s in %.0f ms; paint drift %.3g%%%s\n",
                static_cast<long long>(replay.steps_done()), replay.sim_time(), device.to_string().c_str(), wall_ms,
                100.0 * drift, nonfinite ? " (non-finite steps contained)" : "");
  return nonfinite ? 3 : 0;
}

/// `wetbrush soak`: the stroke files replayed back to back, each on a fresh simulator, for a
/// given time (docs/PERFORMANCE.md "Soak"): what a long session must not do is grow its memory,
/// slow down or let its books drift.
struct SoakArgs {
  std::vector<std::string> strokes;
  double minutes = 60.0;
  std::string device = "auto";
  std::string json;
  double progress_every = 10.0;
};

/// Resident memory of this process, bytes, and the part of it backed by files (the program's and
/// its libraries' code and read-only data, paged in as code first runs; Linux /proc/self/statm).
struct Resident {
  double all = 0, file = 0;
};
Resident resident_bytes() {
  std::ifstream f("/proc/self/statm");
  long long pages_total = 0, pages_resident = 0, pages_shared = 0;
  f >> pages_total >> pages_resident >> pages_shared;
  const double page = double(sysconf(_SC_PAGESIZE));
  return {double(pages_resident) * page, double(pages_shared) * page};
}

int run_soak(const SoakArgs& s) {
  WB_REQUIRE(std::isfinite(s.minutes) && s.minutes > 0.0 && s.minutes <= 24 * 60, "--minutes must be in (0, 1440]");
  const Device device = resolve_device(s.device);
  std::vector<Stroke> strokes;
  for (const std::string& path : s.strokes) strokes.push_back(load_stroke(path));
  // glibc keeps freed small blocks in a cache per thread (up to 7 of each size): they count as
  // live and fill over the first hour, a few KiB a cycle, which reads as growth. Measured with
  // the caches off the heap is flat (docs/PERFORMANCE.md "Soak").
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (!tunables || !std::strstr(tunables, "glibc.malloc.tcache_count=0"))
    std::printf("soak: the C library's per-thread caches are on; they fill over the first hour and show as growth "
                "(GLIBC_TUNABLES=glibc.malloc.tcache_count=0 measures the program's own memory)\n");
  struct Run {
    int cycle;
    size_t stroke;
    int64_t steps;
    double step_ms, drift, rss, rss_file, heap, held;
    int64_t nonfinite;
  };
  std::vector<Run> runs;
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  for (int cycle = 0; cycle == 0 || elapsed() < s.minutes * 60.0; ++cycle) {
    for (size_t i = 0; i < strokes.size(); ++i) {
      ReplayArgs a;
      a.device = s.device;
      Run r{cycle, i, 0, 0, 0, 0, 0, 0, 0, 0};
      {
        const SimConfig cfg = replay_config(a, strokes[i], device);
        configure_stroke(strokes[i], cfg);
        Session session(cfg, start_pose(strokes[i]));
        session.begin_replay(strokes[i]);
        const Replay& replay = *session.replay();
        std::vector<double> ms;
        Progress progress(true, s.progress_every);
        const std::string what = "cycle " + std::to_string(cycle) + "  " + s.strokes[i];
        for (;;) {
          const auto ts = std::chrono::steady_clock::now();
          if (!session.advance()) break;
          ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - ts).count());
          char detail[64];
          std::snprintf(detail, sizeof detail, "%.0f s into the soak", elapsed());
          progress.step(replay.steps_done(), replay.step_count(), what, detail);
        }
        progress.finish();
        session.settle();
        const Simulator& sim = session.sim();
        r.steps = int64_t(ms.size());
        if (!ms.empty()) {
          std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
          r.step_ms = ms[ms.size() / 2];
        }
        r.drift = std::fabs(sim.books().max_drift());
        r.nonfinite = sim.counters().nonfinite_events;
      }
      // After the simulator is gone: what the process and the backend still hold. The C library
      // keeps freed memory for reuse (its mmap threshold rises after large frees); returning it
      // first makes the resident figure what is live, so a leak shows as growth.
      malloc_trim(0);
      const Resident res = resident_bytes();
      r.rss = res.all;
      r.rss_file = res.file;
      const struct mallinfo2 mi = mallinfo2();
      r.heap = double(mi.uordblks + mi.hblkhd);  // live C-library allocations, the process's own data
      r.held = double(mem::usage(!device.is_cpu()).in_use);
      runs.push_back(r);
      std::printf("cycle %d  %-28s %5lld steps  %8.2f ms/step  drift %.1e  resident %7.1f MiB (files %6.1f MiB)  "
                  "heap %8.1f KiB  held %6.1f MiB  %.0f s\n",
                  cycle, s.strokes[i].c_str(), static_cast<long long>(r.steps), r.step_ms, r.drift, r.rss / 1048576.0,
                  r.rss_file / 1048576.0, r.heap / 1024.0, r.held / 1048576.0, elapsed());
      std::fflush(stdout);
    }
  }
  // Growth against the end of the first cycle (the first replays warm the allocator and caches).
  const size_t n = strokes.size();
  const Run& base = runs[n - 1];
  const Run& last = runs.back();
  const double growth = (last.rss - base.rss) / base.rss;
  double worst_drift = 0, worst_slowdown = 0, max_held = 0;
  int64_t nonfinite = 0;
  for (const Run& r : runs) {
    worst_drift = std::max(worst_drift, r.drift);
    nonfinite += r.nonfinite;
    max_held = std::max(max_held, r.held);
  }
  const int cycles = last.cycle + 1;
  if (cycles >= 2)
    for (size_t i = 0; i < n; ++i) {
      const Run& first = runs[i];
      const Run& end = runs[runs.size() - n + i];
      if (first.step_ms > 0) worst_slowdown = std::max(worst_slowdown, end.step_ms / first.step_ms - 1.0);
    }
  std::printf("soak: %d cycles of %zu strokes in %.0f s; resident memory %+.2f %% since the first cycle "
              "(%.1f -> %.1f MiB); backend memory held between replays at most %.1f MiB; step time of the last cycle "
              "against the first at most %+.1f %%; books drift at most %.1e; %lld non-finite events\n",
              cycles, n, elapsed(), 100.0 * growth, base.rss / 1048576.0, last.rss / 1048576.0, max_held / 1048576.0,
              100.0 * worst_slowdown, worst_drift, static_cast<long long>(nonfinite));
  if (!s.json.empty()) {
    nlohmann::json j{{"device", device.to_string()}, {"cycles", cycles}, {"seconds", elapsed()},
                     {"resident_growth", growth}, {"backend_held_max_bytes", max_held},
                     {"step_time_slowdown_max", worst_slowdown}, {"drift_max", worst_drift},
                     {"nonfinite_events", nonfinite}, {"runs", nlohmann::json::array()}};
    for (const Run& r : runs)
      j["runs"].push_back({{"cycle", r.cycle}, {"stroke", s.strokes[r.stroke]}, {"steps", r.steps},
                           {"step_ms_median", r.step_ms}, {"drift", r.drift}, {"resident_bytes", r.rss},
                           {"resident_file_bytes", r.rss_file}, {"heap_bytes", r.heap},
                           {"backend_held_bytes", r.held}});
    write_file_atomic(s.json, j.dump(2) + "\n");
  }
  // The bounds of docs/PERFORMANCE.md "Soak": memory flat within 1 %, books closed, finite.
  const bool ok = (cycles < 2 || growth <= 0.01) && worst_drift <= 1e-4 && nonfinite == 0;
  if (!ok) std::fprintf(stderr, "wetbrush soak: FAILED (memory growth, books drift or non-finite events)\n");
  return ok ? 0 : 1;
}

}  // namespace

void register_replay(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  CLI::App* sub = app.add_subcommand("replay", "Replay a stroke file (JSON or MyPaint dump) headless");
  sub->add_option("STROKES", args->strokes, "Stroke file: wetbrush JSON or MyPaint 't x y pressure' dump")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("-o,--output", args->image, "Write the painting, top view of the stroke's region (PNG)");
  sub->add_option("--save", args->save, "Save the painting as OpenRaster (.ora) with its paint volume");
  sub->add_option("--stats", args->stats, "Write replay statistics (JSON)");
  sub->add_option("--brush-image", args->brush_image,
                  "Write the brush picture: bristles of the final pose over every cell they touched (PNG)");
  sub->add_option("--frames", args->frames_dir, "Write a rendered PNG frame every --every steps into this folder");
  sub->add_option("--every", args->every, "Frame interval in steps")->capture_default_str();
#if WB_WITH_MEDIA  // the time-lapse (src/media; not in a -DWB_MEDIA=OFF build)
  sub->add_option("--video", args->video, "Write a time-lapse video (H.264 MP4) of the replay");
  sub->add_option("--fps", args->fps, "Time-lapse frames per second")->capture_default_str();
  sub->add_option("--speed", args->speed, "Time-lapse speed: simulated seconds per second of video")
      ->capture_default_str();
  sub->add_option("--camera", args->video_camera, "Time-lapse view: top or oblique")
      ->check(CLI::IsMember({"top", "oblique"}))
      ->capture_default_str();
#endif
  sub->add_option("--brush", args->brush_shape,
                  "Replace the stroke's brush by the default brush of this shape "
                  "(round, flat, fan, filbert, angular, mop, rigger)");
  sub->add_option("--color", args->color, "Paint colour on the brush, RYB in [0, 1]: R,Y,B")->delimiter(',');
  sub->add_option("--oil", args->oil, "Oil fraction of the paint on the brush, [0, 1]");
  sub->add_option("--load", args->load, "How full the brush is loaded, fraction of capacity [0, 1]");
  sub->add_flag("--no-reload", args->no_reload, "Load the brush once, not at every pen-down (it runs dry)");
  sub->add_flag("--grid-only", args->grid_only, "No particles: paint lives on the grid only (paper Fig. 7a/c)");
  sub->add_option("--window", args->window, "Active window size X,Y,Z in cells (default 160,160,32)")->delimiter(',');
  sub->add_option("--set", args->sets, "Set a parameter, id=value (see `wetbrush params`); repeatable");
  sub->add_option("--params", args->params_file, "Read parameters from a JSON file (`wetbrush params --json`)");
  sub->add_flag("-q,--quiet", args->quiet, "No progress or summary output");
  add_progress_option(sub, args->progress_every);
  add_device_option(sub, args->device);
  set_action(sub, [args]() { return run_replay(*args); });

  auto bench = std::make_shared<ReplayArgs>();
  bench->bench = true;
  CLI::App* b = app.add_subcommand(
      "bench", "Time a stroke file's simulation per stage (median, p90, share of the step), its step rate and memory");
  b->add_option("STROKES", bench->strokes, "Stroke file: wetbrush JSON or MyPaint dump")->required()->check(CLI::ExistingFile);
  b->add_option("--json", bench->bench_json, "Also write the figures as JSON");
  b->add_flag("--grid-only", bench->grid_only, "No particles: paint lives on the grid only");
  b->add_option("--window", bench->window, "Active window size X,Y,Z in cells")->delimiter(',');
  b->add_option("--set", bench->sets, "Set a parameter, id=value (see `wetbrush params`); repeatable");
  b->add_option("--params", bench->params_file, "Read parameters from a JSON file");
  b->add_flag("-q,--quiet", bench->quiet, "No progress output");
  add_progress_option(b, bench->progress_every);
  add_device_option(b, bench->device);
  set_action(b, [bench]() { return run_replay(*bench); });

  auto soak = std::make_shared<SoakArgs>();
  CLI::App* k = app.add_subcommand(
      "soak", "Replay stroke files back to back, each on a fresh simulator, for a while: memory, step time and books");
  k->add_option("STROKES", soak->strokes, "Stroke files (wetbrush JSON or MyPaint dump)")
      ->required()
      ->check(CLI::ExistingFile);
  k->add_option("--minutes", soak->minutes, "How long to keep going (whole cycles; at least one)")->capture_default_str();
  k->add_option("--json", soak->json, "Also write every run's figures as JSON");
  add_progress_option(k, soak->progress_every);
  add_device_option(k, soak->device);
  set_action(k, [soak]() { return run_soak(*soak); });
}

}  // namespace wb::cli
