// wetbrush studio: the desktop painting application (Qt 6 Widgets; an OpenGL canvas view, or a
// QPainter one where no OpenGL context can be made).
#include <QApplication>
#include <QThread>
#include <QBuffer>
#include <QCommandLineParser>
#include <QElapsedTimer>
#include <QSurfaceFormat>
#include <QTimer>

#include <cstdio>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/exec/device.h"
#include "core/exec/error.h"
#include "core/exec/memory.h"
#include "core/io/atomic_file.h"
#include "studio/demo.h"
#include "studio/main_window.h"

using namespace wb::studio;

namespace {

/// True when the command line asks only for the help or the version: answered without a display.
bool asks_for_help_or_version(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--") break;
    if (a == "-h" || a == "--help" || a == "--help-all" || a == "-v" || a == "--version") return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  QCoreApplication::setApplicationName("wetbrush-studio");
  QCoreApplication::setOrganizationName("wetbrush");
  QCoreApplication::setApplicationVersion(WB_VERSION);

  QCommandLineParser cli;
  cli.setApplicationDescription("wetbrush studio: paint with a simulated bristle brush and 3D oil paint");
  cli.addHelpOption();
  cli.addVersionOption();
  QCommandLineOption device_opt("device", "Simulation device: auto, cpu, cuda or cuda:N.", "device", "auto");
  QCommandLineOption preset_opt("preset", "Quality preset: auto (gpu on a GPU; cpu from 8 CPU threads, fast below), cpu, gpu, fast (fewer bristles: keeps up on two CPU cores) or tiny (small canvas and brush, for tests).", "preset", "auto");
  QCommandLineOption view_opt("view",
                              "Canvas view: auto (OpenGL when a context can be made, else raster), gl (OpenGL) or "
                              "raster (QPainter, no OpenGL).",
                              "view", "auto");
  QCommandLineOption data_opt("data-dir", "Folder for presets, settings and the recovery file.", "dir");
  QCommandLineOption norecover_opt("no-recovery", "Do not offer to recover an autosaved painting.");
  QCommandLineOption demo_opt("demo-screenshot",
                              "Paint a scripted picture with synthesised tablet strokes, save a screenshot of "
                              "the window to FILE and quit.",
                              "file");
  QCommandLineOption stats_opt("demo-stats",
                               "With --demo-screenshot: write the view frame rate, the simulation rate and the "
                               "pen-to-paint latency of the scripted painting to FILE (JSON).",
                               "file");
  QCommandLineOption rec_opt("demo-recording",
                             "With --demo-screenshot: save the canvas's recording of the scripted painting to FILE "
                             "(a stroke file `wetbrush bench` and `wetbrush replay` take).",
                             "file");
  QCommandLineOption short_opt("demo-short",
                               "With --demo-screenshot: a short scripted painting, one stroke on the canvas and "
                               "none on the palette (a test that the demo runs).");
  QCommandLineOption autosave_opt("autosave-interval", "Seconds between autosaves of a changed painting (default 180).",
                                  "seconds", "180");
  QCommandLineOption loop_opt("paint-loop",
                              "Paint scripted tablet strokes without end, announcing each on standard output when the "
                              "pen goes down and when it lifts (the autosave and recovery test kills the studio "
                              "mid-stroke).");
  QCommandLineOption memory_opt("memory-limit",
                                "Most memory the paintings may hold, host and GPU each (e.g. 4G, 512M); without it, "
                                "what the machine has available (also WB_MEMORY_LIMIT).",
                                "size");
  cli.addOptions({device_opt, preset_opt, view_opt, data_opt, norecover_opt, autosave_opt, demo_opt, stats_opt,
                  rec_opt, short_opt, loop_opt, memory_opt});
  cli.addPositionalArgument("painting", "OpenRaster painting to open (.ora).", "[painting]");
  if (asks_for_help_or_version(argc, argv)) {
    // The help and the version need no display: a core application parses, prints and exits.
    QCoreApplication core(argc, argv);
    cli.process(core);
    return 0;
  }

  QApplication::setAttribute(Qt::AA_ShareOpenGLContexts);
  QApplication app(argc, argv);
  cli.process(app);

  StudioOptions opt;
  try {
    opt.device = wb::Device::parse(cli.value(device_opt).toStdString());
    opt.preset = QualityPreset::from_name(cli.value(preset_opt).toStdString(), opt.device);
    const QString limit = cli.isSet(memory_opt) ? cli.value(memory_opt) : qEnvironmentVariable("WB_MEMORY_LIMIT");
    wb::mem::set_budget_from(limit.toStdString());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wetbrush-studio: %s\n", wb::user_message(e).c_str());
    return 2;
  }
  const std::optional<ViewKind> view = parse_view_kind(cli.value(view_opt));
  if (!view) {
    std::fprintf(stderr, "wetbrush-studio: --view: expected auto, gl or raster, got '%s'\n", qPrintable(cli.value(view_opt)));
    return 2;
  }
  opt.view = *view;
  if (opt.view == ViewKind::Gl && !opengl_available()) {
    std::fprintf(stderr, "wetbrush-studio: --view gl: no OpenGL view on the '%s' platform (it composes no OpenGL, or "
                 "no context can be made); use --view raster or auto\n", qPrintable(QGuiApplication::platformName()));
    return 2;
  }
  bool interval_ok = false;
  opt.autosave_interval_s = cli.value(autosave_opt).toInt(&interval_ok);
  if (!interval_ok || opt.autosave_interval_s < 1 || opt.autosave_interval_s > 86400) {
    std::fprintf(stderr, "wetbrush-studio: --autosave-interval: expected whole seconds from 1 to 86400, got '%s'\n",
                 qPrintable(cli.value(autosave_opt)));
    return 2;
  }
  // The demo's other options mean nothing without it: say so instead of opening an idle studio.
  for (const QCommandLineOption* o : {&stats_opt, &rec_opt, &short_opt}) {
    if (cli.isSet(*o) && !cli.isSet(demo_opt)) {
      std::fprintf(stderr, "wetbrush-studio: --%s needs --demo-screenshot FILE (it measures the scripted painting)\n",
                   qPrintable(o->names().first()));
      return 2;
    }
  }
  opt.data_dir = cli.value(data_opt);
  opt.offer_recovery = !cli.isSet(norecover_opt) && !cli.isSet(demo_opt) && !cli.isSet(loop_opt);
  if (!cli.positionalArguments().isEmpty()) opt.open_path = cli.positionalArguments().first();

  MainWindow w(opt);
  w.show();
  if (cli.isSet(demo_opt)) {
    const QString out = cli.value(demo_opt), stats = cli.value(stats_opt), recording = cli.value(rec_opt);
    const bool short_demo = cli.isSet(short_opt);
    QTimer::singleShot(500, &w, [&w, out, stats, recording, short_demo, &opt] {
      // Also the frame-rate and simulation-rate measurement of docs/perf/studio.md.
      w.settle();
      QElapsedTimer timer;
      timer.start();
      const int64_t frames0 = w.view()->frames_drawn(), latency0 = w.view()->latency().count(),
                    pal_latency0 = w.palette()->view()->latency().count();
      const SimStatus st0 = w.sim()->status(), pal0 = w.palette()->sim()->status();
      const DemoTimes t = run_demo_painting(w, short_demo);
      w.settle();
      QApplication::processEvents();
      const double secs = timer.elapsed() / 1000.0;
      const SimStatus st = w.sim()->status(), pal = w.palette()->sim()->status();
      const int64_t frames = w.view()->frames_drawn() - frames0, steps = st.steps - st0.steps,
                    pal_steps = pal.steps - pal0.steps;
      // Each surface's rate over its own strokes (pen down until its simulation caught up): the
      // canvas's is the painter's real-time factor; the palette's mixing is reported beside it.
      const double sim_s = double(steps) * kStepDt, pal_sim_s = double(pal_steps) * kStepDt;
      const double rtf = t.canvas_s > 0 ? sim_s / t.canvas_s : 0.0;
      const double pal_rtf = t.palette_s > 0 ? pal_sim_s / t.palette_s : 0.0;
      // A step's mean over the painting (the status bar's median is of its last half second).
      const double mean_ms = steps > 0 ? 1e3 * (st.times.step - st0.times.step) / double(steps) : 0.0;
      const double pal_mean_ms = pal_steps > 0 ? 1e3 * (pal.times.step - pal0.times.step) / double(pal_steps) : 0.0;
      // The canvas's view draws when the canvas's simulation publishes: its rate is over those strokes.
      const double fps = t.canvas_s > 0 ? double(frames) / t.canvas_s : 0.0;
      // Pen-to-paint latency of each surface's pen events (docs/STUDIO.md "Pen-to-paint latency").
      const LatencySummary lat = w.view()->latency().summary(latency0),
                           pal_lat = w.palette()->view()->latency().summary(pal_latency0);
      // Its parts, over the same events.
      const auto part = [&](LatencyPart p) {
        const LatencySummary s = w.view()->latency().summary(latency0, p);
        return nlohmann::json{{"median_ms", s.median_ms}, {"p95_ms", s.p95_ms}};
      };
      const nlohmann::json lat_parts = {{"to_step", part(LatencyPart::to_step)},
                                        {"to_frame", part(LatencyPart::to_frame)},
                                        {"to_screen", part(LatencyPart::to_screen)}};
      const char* view_name = view_kind_name(w.view()->kind());
      std::printf("demo: %.1f s wall (pen on the canvas or palette %.1f s), %lld view frames (%.1f fps over the "
                  "canvas's strokes, %s view), device %s, preset %s\n",
                  secs, t.pen_s, (long long)frames, fps, view_name, st.device.c_str(), opt.preset.name.c_str());
      std::printf("demo: pen-to-paint latency: canvas median %.1f ms, p95 %.1f ms (%lld pen events); palette median "
                  "%.1f ms, p95 %.1f ms (%lld)\n",
                  lat.median_ms, lat.p95_ms, (long long)lat.count, pal_lat.median_ms, pal_lat.p95_ms,
                  (long long)pal_lat.count);
      std::printf("demo: canvas latency's parts (median, p95 ms): %s\n", lat_parts.dump().c_str());
      std::printf("demo: canvas: %lld simulation steps in %.1f s of its strokes (real-time factor %.3f, %.1f ms "
                  "a step on average, %.1f the median of the last half second), %lld particles at the end\n",
                  (long long)steps, t.canvas_s, rtf, mean_ms, st.step_ms, (long long)st.particles);
      std::printf("demo: palette: %lld simulation steps in %.1f s of its strokes (real-time factor %.3f, %.1f ms "
                  "a step on average, %.1f the median of the last half second)\n",
                  (long long)pal_steps, t.palette_s, pal_rtf, pal_mean_ms, pal.step_ms);
      const auto times = [](const SimStatus& a, const SimStatus& b) {
        return nlohmann::json{{"commands", b.times.commands - a.times.commands},
                              {"player", b.times.player - a.times.player},
                              {"undo", b.times.undo - a.times.undo},
                              {"step", b.times.step - a.times.step},
                              {"render", b.times.render - a.times.render},
                              {"idle", b.times.idle - a.times.idle}};
      };
      const nlohmann::json worker = times(st0, st), pal_worker = times(pal0, pal);
      std::printf("demo: canvas's simulation thread, s: %s\ndemo: palette's simulation thread, s: %s\n",
                  worker.dump().c_str(), pal_worker.dump().c_str());
      try {
        if (!stats.isEmpty()) {
          const nlohmann::json j = {{"preset", opt.preset.name}, {"device", st.device},
                                    {"view", view_name},
                                    {"wall_s", secs},         {"pen_s", t.pen_s},
                                    {"view_frames", frames},  {"view_fps", fps},
                                    {"latency_median_ms", lat.median_ms}, {"latency_p95_ms", lat.p95_ms},
                                    {"latency_events", lat.count}, {"latency_parts", lat_parts},
                                    {"canvas_s", t.canvas_s}, {"steps", steps},
                                    {"simulated_s", sim_s},   {"real_time_factor", rtf},
                                    {"mean_step_ms", mean_ms}, {"last_median_step_ms", st.step_ms},
                                    {"median_step_ms", st.step_times.quantile_since(st0.step_times, 0.5)},
                                    {"p95_step_ms", st.step_times.quantile_since(st0.step_times, 0.95)},
                                    {"particles_end", st.particles},
                                    {"worker_s", worker},
                                    {"palette", {{"strokes_s", t.palette_s}, {"steps", pal_steps},
                                                 {"simulated_s", pal_sim_s}, {"real_time_factor", pal_rtf},
                                                 {"mean_step_ms", pal_mean_ms}, {"last_median_step_ms", pal.step_ms},
                                                 {"median_step_ms", pal.step_times.quantile_since(pal0.step_times, 0.5)},
                                                 {"p95_step_ms", pal.step_times.quantile_since(pal0.step_times, 0.95)},
                                                 {"latency_median_ms", pal_lat.median_ms},
                                                 {"latency_p95_ms", pal_lat.p95_ms},
                                                 {"latency_events", pal_lat.count},
                                                 {"worker_s", pal_worker}}}};
          wb::write_file_atomic(stats.toStdString(), j.dump(2) + "\n");
        }
        if (!recording.isEmpty() && !w.save_recording(recording))
          throw std::runtime_error("cannot save the recording to " + recording.toStdString());
        // The picture: the painting under a raking light, with the oblique view beside it.
        const int renders = w.oblique_renders();
        w.view_panel()->rake();
        w.view_panel()->set_oblique(true);
        QElapsedTimer wait;
        wait.start();
        while (w.oblique_renders() <= renders && wait.elapsed() < 60000) {
          QApplication::processEvents(QEventLoop::AllEvents, 50);
          QThread::msleep(10);
        }
        w.settle();
        QApplication::processEvents();
        QByteArray png;
        QBuffer buffer(&png);
        buffer.open(QIODevice::WriteOnly);
        w.grab().save(&buffer, "PNG");
        wb::write_file_atomic(out.toStdString(), png.constData(), size_t(png.size()));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "wetbrush-studio: %s\n", wb::user_message(e).c_str());
        QApplication::exit(1);
        return;
      }
      std::printf("wrote %s\n", qPrintable(out));
      w.undo_stack()->setClean();
      QApplication::quit();
    });
  }
  if (cli.isSet(loop_opt)) {
    QObject::connect(w.view(), &CanvasView::penPress, [](PenInput, double) {
      std::printf("paint-loop: pen down\n");
      std::fflush(stdout);
    });
    QObject::connect(w.view(), &CanvasView::penRelease, [](PenInput, double) {
      std::printf("paint-loop: pen up\n");
      std::fflush(stdout);
    });
    // Events are processed within each stroke, so closing the window ends the loop.
    QTimer::singleShot(500, &w, [&w] {
      for (int k = 0; w.isVisible(); ++k) paint_loop_stroke(w, k);
    });
  }
  return app.exec();
}
