// Studio tests (Qt Test, run under xvfb-run for Mesa OpenGL): the window opens with an OpenGL
// canvas, and with the raster one on request or where there is no OpenGL (the offscreen demo,
// with its pen-to-paint latency); synthesised tablet strokes paint under their path only; pressure widens the stroke;
// undo / redo restore the exact canvas; save then open gives the same volume; a recorded
// session replays to the same canvas; closing with unsaved changes asks; the real studio killed
// mid-stroke recovers its last autosave; a save that fails (read-only folder, file size limit)
// keeps the old file and the painting open and unsaved. Each test function stands alone: CTest
// runs each in a process of its own (cmake/StudioTests.cmake).
#include <QApplication>
#include <QDoubleSpinBox>
#include <QSpinBox>
#include <QDir>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QLineEdit>
#include <QMenuBar>
#include <QFile>
#include <QMessageBox>
#include <QSettings>
#include <QOpenGLContext>
#include <QOpenGLWidget>
#include <QProcess>
#include <QSignalSpy>
#include <QPushButton>
#include <QTemporaryDir>
#include <QTest>
#include <QThread>
#include <QTimer>
#include <QToolButton>

#if WB_WITH_MEDIA
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
extern "C" {
#include <libavformat/avformat.h>
}
#include <tiny_gltf.h>
#endif
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <functional>
#include <future>
#include <nlohmann/json.hpp>
#include <numeric>
#include <omp.h>
#include <optional>
#include <tuple>

#include "core/color/ryb.h"
#include "core/exec/fault.h"
#include "core/exec/memory.h"
#include "core/io/brush_json.h"
#include "core/io/document.h"
#include "core/io/stroke.h"
#include "studio/demo.h"
#include "studio/main_window.h"
#include "studio/pen_clock.h"

using namespace wb;
using namespace wb::studio;

namespace {

/// Runs fn on the simulation thread and waits for its result.
template <class F>
auto on_thread(SimThread& t, F fn) {
  using R = decltype(fn(t));
  auto p = std::make_shared<std::promise<R>>();
  t.post([p, fn](SimThread& s) mutable { p->set_value(fn(s)); });
  return p->get_future().get();
}
template <class F>
auto on_sim(MainWindow& w, F fn) {
  return on_thread(*w.sim(), fn);
}

/// Mass-weighted pigment (RYB) of the paint that is not dried, over the canvas, and its amount.
std::pair<Vec3, double> wet_pigment(TileStore& c) {
  Vec3 sum{};
  double m = 0;
  for (int id : c.allocated_tile_ids()) {
    const TileData t = c.read_tile(id);
    for (size_t i = 0; i < t.density.size(); ++i) {
      if (t.density[i] <= 0.f || t.dryness[i] == 65535) continue;
      const float d = t.density[i];
      sum = sum + Vec3(decode_unorm16(t.pigment_r[i]), decode_unorm16(t.pigment_y[i]), decode_unorm16(t.pigment_b[i])) * d;
      m += d;
    }
  }
  return {m > 0 ? sum * float(1.0 / m) : Vec3{}, m};
}

/// Column paint (sum of density over z) per canvas cell.
/// Paint per column (cell volumes); with `wet_only`, the paint that is not dried (a stroke's,
/// not the canvas's ground).
std::vector<float> column_density(TileStore& c, bool wet_only = false) {
  const CanvasDims d = c.dims();
  std::vector<float> col(size_t(d.width) * d.height, 0.f);
  for (int id : c.allocated_tile_ids()) {
    const TileData t = c.read_tile(id);
    for (int z = 0; z < d.depth; ++z)
      for (int ly = 0; ly < kTileSize; ++ly)
        for (int lx = 0; lx < kTileSize; ++lx) {
          const int x = t.tile_x * kTileSize + lx, y = t.tile_y * kTileSize + ly;
          const size_t i = (size_t(z) * kTileSize + ly) * kTileSize + lx;
          if (x < d.width && y < d.height && !(wet_only && t.dryness[i] == 65535))
            col[size_t(y) * d.width + x] += t.density[i];
        }
  }
  return col;
}

/// Column paint of the studio's canvas with its paint at rest.
std::vector<float> column_density(MainWindow& w, bool wet_only = false) {
  return on_sim(w, [wet_only](SimThread& s) {
    TileStore c = s.sim().settled_canvas_copy(Device{});
    return column_density(c, wet_only);
  });
}

/// The paint volume as a file stores it, without tiles that are all zero (an undo writes a
/// tile that did not exist back as an empty one).
std::vector<uint8_t> canonical_volume(TileStore& c, bool with_dryness = true) {
  TileStore copy(Device{}, c.dims());
  for (int id : c.allocated_tile_ids()) {
    TileData t = c.read_tile(id);
    if (!with_dryness) std::fill(t.dryness.begin(), t.dryness.end(), uint16_t(0));
    const auto nonzero = [](const auto& v) { return std::any_of(v.begin(), v.end(), [](auto x) { return x != 0; }); };
    if (nonzero(t.density) || nonzero(t.pigment_r) || nonzero(t.pigment_y) || nonzero(t.pigment_b) ||
        nonzero(t.oil) || nonzero(t.dryness))
      copy.write_tile(t);
  }
  return encode_volume(copy);
}

/// The studio's paint volume with its paint at rest (what a save writes); without the dryness,
/// the paint alone (the painting keeps drying while it is painted and undone).
std::vector<uint8_t> volume_bytes(MainWindow& w, bool with_dryness = true) {
  return on_sim(w, [with_dryness](SimThread& s) {
    TileStore c = s.sim().settled_canvas_copy(Device{});
    return canonical_volume(c, with_dryness);
  });
}

/// Painted width across the column x within rows [y0, y1): the cells holding a mark (more than
/// a twentieth of a cell of paint). Counted rather than spanned, so that a fleck thrown off at
/// lift-off (docs/STUDIO.md) adds a cell, not the distance to it.
int painted_width(const std::vector<float>& col, int width, int height, int x, int y0, int y1) {
  int n = 0;
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y) n += col[size_t(y) * width + x] > 0.05f;
  return n;
}

QByteArray read_bytes(const QString& path) {
  QFile f(path);
  return f.open(QIODevice::ReadOnly) ? f.readAll() : QByteArray();
}

/// Temporary files of saves (`.NAME.tmp-PID-XXXXXX`) left in a folder.
QStringList save_temporaries(const QString& folder) {
  return QDir(folder).entryList({"*.tmp-*"}, QDir::Files | QDir::Hidden);
}

/// Answers the window's modal message boxes as they open (a timer polls for them, since they
/// block the caller), and records each one's title and text.
class BoxAnswerer {
 public:
  struct Box {
    QString title, text;
  };
  explicit BoxAnswerer(std::function<QMessageBox::StandardButton(QMessageBox&)> answer) : answer_(std::move(answer)) {
    QObject::connect(&timer_, &QTimer::timeout, [this] {
      auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
      if (!box || !box->isVisible()) return;
      boxes.push_back({box->windowTitle(), box->text()});
      if (QAbstractButton* b = box->button(answer_(*box)))
        b->click();
      else
        box->reject();  // an unexpected box: recorded, and closed so that the test goes on
    });
    timer_.start(20);
  }
  QString titles() const {
    QStringList t;
    for (const Box& b : boxes) t << b.title;
    return t.join(", ");
  }
  std::vector<Box> boxes;

 private:
  std::function<QMessageBox::StandardButton(QMessageBox&)> answer_;
  QTimer timer_;
};

/// Gives a folder made read-only by a test its write permission back (QTemporaryDir must
/// remove it), however the test ends.
struct WritableAgain {
  QString folder;
  ~WritableAgain() { QFile::setPermissions(folder, QFile::ReadOwner | QFile::WriteOwner | QFile::ExeOwner); }
};

/// Set in the child process of failedSaveAtFileSizeLimitKeepsPainting.
constexpr const char* kFileSizeChildEnv = "WB_STUDIO_TEST_FILE_SIZE_CHILD";

}  // namespace

class StudioTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<QTemporaryDir> dir_;  ///< made by initTestCase (listing the functions makes none)
  std::unique_ptr<MainWindow> w_;
  // The tiny preset: the studio's input path, undo, files and recording at a scale where a
  // stroke simulates in seconds on two CPU cores (canvas 160 x 120 x 16, window 32 x 32 x 8,
  // round brush of 40 bristles, 16 cells long and 8 wide).
  const QualityPreset preset_ = QualityPreset::tiny();
  const BrushSpec brush_ = preset_.start_brush();
  const int kW = preset_.canvas_width, kH = preset_.canvas_height;
  /// Farthest a mark can reach from the path: the bristles splay by at most their length
  /// around the ferrule (half the width), plus a cell of paint flow.
  const int reach_ = int(std::ceil(brush_.length + 0.5f * brush_.width)) + 1;

  StudioOptions options() {
    StudioOptions o;
    o.device = Device::parse("cpu");
    o.preset = preset_;
    o.data_dir = dir_->path() + "/data";
    o.offer_recovery = false;
    return o;
  }

  /// A straight stroke at constant pressure along y: 48 tablet samples 20 ms apart (about
  /// 100 cells, 2 cm, in a second).
  void stroke(float y, float pressure, float x0 = 30.f, float x1 = 130.f) {
    QElapsedTimer t;
    t.start();
    tablet_stroke(w_->view(), line_points(QPointF(x0, y), QPointF(x1, y), 48, pressure), 20);
    w_->settle();
    const SimStatus st = w_->sim()->status();
    const PaintCensus c = on_sim(*w_, [](SimThread& s) { return s.sim().census(); });
    qInfo("stroke: %lld ms wall, %lld steps so far, %.1f ms/step, %lld particles; paint kg: grid %.4g, particles %.4g, bristles %.4g", (long long)t.elapsed(),
          (long long)st.steps, st.step_ms, (long long)st.particles, c.grid, c.particles, c.bristles);
    qInfo("simulation thread so far, s: step %.1f, render %.1f, undo %.1f, player %.1f, commands %.1f, idle %.1f",
          st.times.step, st.times.render, st.times.undo, st.times.player, st.times.commands, st.times.idle);
  }

  /// Paints a stroke on a new canvas and saves it to `path` (the old file of a failed save).
  void paint_and_save(const QString& path) {
    grid_only_canvas(false);
    stroke(40.f, 0.6f);
    QVERIFY(w_->save_to(path, true));
    QVERIFY(!w_->modified());
    // A second stroke, not saved: the painting that a failed save must keep.
    stroke(80.f, 0.7f, 20.f, 140.f);
    QVERIFY(w_->modified());
  }

  /// Saves over `path` while saves fail: each gives a clear error naming the file and `why`,
  /// leaves the file byte for byte as `old_file` with no temporary file beside it, and keeps
  /// the painting open, unchanged and marked unsaved. Through both save paths (waiting, as
  /// closing does; on a worker, as File > Save), and closing while such a save is written
  /// waits for it and then asks about the unsaved painting.
  void expect_failed_saves(const QString& path, const QByteArray& old_file, const std::vector<uint8_t>& painting,
                           const QString& why) {
    const QString folder = QFileInfo(path).absolutePath();
    const QString title = QFileInfo(path).fileName() + " *";
    // Ok to the error; Cancel to "save the changes?", so that the window stays open.
    BoxAnswerer answer(
        [](QMessageBox& b) { return b.button(QMessageBox::Cancel) ? QMessageBox::Cancel : QMessageBox::Ok; });
    const auto kept = [&](const char* how) {
      QVERIFY2(answer.boxes.size() == 1 && answer.boxes[0].title == "Save failed",
               qPrintable(QString("%1: one error box, got: %2").arg(how, answer.titles())));
      const QString msg = answer.boxes[0].text;
      qInfo("%s: \"%s\"", how, qPrintable(QString(msg).replace('\n', ' ')));
      QVERIFY2(msg.contains(path) && msg.contains(why), qPrintable("the error names the file and " + why + ": " + msg));
      QVERIFY2(read_bytes(path) == old_file, "the old file is intact, byte for byte");
      QVERIFY2(save_temporaries(folder).isEmpty(),
               qPrintable("temporary files left: " + save_temporaries(folder).join(", ")));
      QVERIFY2(w_->modified(), "the painting is still marked unsaved");
      QVERIFY2(w_->windowTitle().startsWith(title), qPrintable("the title marks it unsaved: " + w_->windowTitle()));
      QCOMPARE(w_->current_path(), path);
      QVERIFY2(volume_bytes(*w_) == painting, "the painting is open and unchanged");
      answer.boxes.clear();
    };
    QVERIFY2(!w_->save_to(path, true), "a failed save says so");
    kept("waiting save");
    if (QTest::currentTestFailed()) return;
    w_->save_to(path);
    QTRY_VERIFY_WITH_TIMEOUT(!answer.boxes.empty(), 10000);
    kept("save on a worker");
    if (QTest::currentTestFailed()) return;
    w_->save_to(path);
    QVERIFY2(!w_->close(), "closing with a failing save in flight keeps the window");
    QVERIFY2(answer.boxes.size() == 2 && answer.boxes[0].title == "Save failed" &&
                 answer.boxes[1].title == "Unsaved changes",
             qPrintable("closing waits for the save's error, then asks; got: " + answer.titles()));
    QVERIFY(w_->isVisible());
    QVERIFY(w_->modified());
  }

  /// Once saves work again, a save holds the painting that was kept open.
  void expect_save_after_repair(const QString& path, const std::vector<uint8_t>& painting) {
    QVERIFY(w_->save_to(path, true));
    QVERIFY(!w_->modified());
    Painting saved = load_painting(path.toStdString(), Device::parse("cpu"));
    QVERIFY2(canonical_volume(saved.canvas) == painting, "the next save holds the painting");
  }

 private Q_SLOTS:
  void initTestCase() {
    dir_ = std::make_unique<QTemporaryDir>();
    QVERIFY(dir_->isValid());

    w_ = std::make_unique<MainWindow>(options());
    w_->show();
    QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    w_->settle();
  }

  void windowOpensWithOpenGL() {
    QCOMPARE(w_->view()->kind(), ViewKind::Gl);  // auto: Xvfb's Mesa makes a context
    QOpenGLWidget* gl = w_->view()->gl_widget();
    QVERIFY(gl != nullptr);
    QVERIFY(gl->context() != nullptr);
    QVERIFY(gl->context()->isValid());
    const QImage img = gl->grabFramebuffer();
    QVERIFY(!img.isNull());
    QCOMPARE(w_->view()->canvas_size(), QSize(kW, kH));
    QCOMPARE(w_->sim()->status().device, std::string("cpu"));
  }

  /// `--view raster`: the window has no OpenGL widget at all; a scripted stroke changes the
  /// canvas's pixels on screen, each frame repainting the changed rectangle rather than the view,
  /// and its pen events are timed from the tablet to the screen.
  void rasterViewPaintsAScriptedStroke() {
    StudioOptions o = options();
    o.view = ViewKind::Raster;
    o.data_dir = dir_->path() + "/raster";
    auto w = std::make_unique<MainWindow>(o);
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
    QCOMPARE(w->view()->kind(), ViewKind::Raster);
    QCOMPARE(w->palette()->view()->kind(), ViewKind::Raster);
    QVERIFY(w->view()->gl_widget() == nullptr);
    QVERIFY(w->findChildren<QOpenGLWidget*>().isEmpty());
    // A canvas larger than the changed rectangle of a step (the window and the renderer's reach).
    w->new_canvas(400, 300, QColor(240, 235, 225));
    w->settle();
    w->view()->fit();
    QTest::qWait(100);
    const QImage before = w->view()->grab().toImage();
    const int64_t frames0 = w->view()->frames_drawn(), pixels0 = w->view()->pixels_drawn();
    const int64_t latency0 = w->view()->latency().count();
    const QPointF a(100, 150), b(300, 150);
    tablet_stroke(w->view(), line_points(a, b, 48, 0.7f), 20);
    w->settle(true);
    QTest::qWait(200);  // the last frame's repaint
    const int64_t frames = w->view()->frames_drawn() - frames0, pixels = w->view()->pixels_drawn() - pixels0;
    const LatencySummary lat = w->view()->latency().summary(latency0);
    const QImage after = w->view()->grab().toImage();
    QCOMPARE(after.size(), before.size());
    // Pixels along the stroke's path changed, and not on the far side of the canvas.
    const auto changed = [&](QPointF from, QPointF to) {
      int n = 0, all = 0;
      for (int i = 0; i <= 100; ++i) {
        const QPoint p = w->view()->to_widget(from + (to - from) * (i / 100.0)).toPoint();
        ++all;
        n += before.pixel(p) != after.pixel(p);
      }
      return double(n) / all;
    };
    const double on_path = changed(a + QPointF(10, 0), b - QPointF(10, 0));
    const double far_row = changed(QPointF(20, 280), QPointF(380, 280));
    const double area = double(w->view()->width()) * w->view()->height();
    qInfo("raster view: %lld frames, %.0f %% of the view a frame on average; path pixels changed %.2f, far row %.2f; "
          "latency median %.1f ms, p95 %.1f ms over %lld pen events",
          (long long)frames, frames > 0 ? 100.0 * double(pixels) / double(frames) / area : 0.0, on_path, far_row,
          lat.median_ms, lat.p95_ms, (long long)lat.count);
    QVERIFY2(on_path > 0.9, "the stroke's pixels changed on screen");
    QCOMPARE(far_row, 0.0);
    QVERIFY(frames > 0);
    QVERIFY2(double(pixels) / double(frames) < 0.5 * area, "a frame repaints what changed, not the whole view");
    QVERIFY(lat.count > 0);
    QVERIFY(std::isfinite(lat.median_ms) && lat.median_ms > 0.0 && lat.p95_ms >= lat.median_ms);
    w->undo_stack()->setClean();
  }

  /// Under the offscreen platform and no display there is no OpenGL: the real studio picks the
  /// raster view itself, runs its scripted demo (the short one) to the end and writes the demo's
  /// statistics with the pen-to-paint latency; `--view gl` says why it cannot run there instead of
  /// crashing.
  void helpAndVersionNeedNoDisplay() {
    // No display, no platform chosen: the help and the version still print, and exit 0.
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    for (const char* v : {"DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"}) env.remove(v);
    for (const QStringList& args : {QStringList{"--help"}, QStringList{"--device", "cpu", "-h"}, QStringList{"--version"}}) {
      QProcess studio;
      studio.setProcessEnvironment(env);
      studio.start(WB_STUDIO_PATH, args);
      QVERIFY2(studio.waitForFinished(20000), "answered within 20 s");
      const QString out = QString::fromUtf8(studio.readAllStandardOutput()),
                    err = QString::fromUtf8(studio.readAllStandardError());
      QVERIFY2(studio.exitStatus() == QProcess::NormalExit && studio.exitCode() == 0,
               qPrintable(QString("%1: exit %2, stderr:\n%3").arg(args.join(' ')).arg(studio.exitCode()).arg(err)));
      const bool version = args.contains("--version");
      QVERIFY2(out.contains(version ? "wetbrush-studio 0." : "--preset"), qPrintable(out));
    }
  }

  void offscreenDemoChoosesRasterAndReportsLatency() {
    const QString data = dir_->path() + "/offscreen";
    QVERIFY(QDir().mkpath(data));
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("QT_QPA_PLATFORM", "offscreen");
    env.remove("DISPLAY");
    env.remove("WAYLAND_DISPLAY");
    QProcess studio;
    studio.setProcessEnvironment(env);
    studio.start(WB_STUDIO_PATH, {"--device", "cpu", "--preset", "tiny", "--data-dir", data, "--demo-screenshot",
                                  data + "/demo.png", "--demo-stats", data + "/stats.json", "--demo-short"});
    QVERIFY2(studio.waitForFinished(120000), "the demo finished within two minutes");
    const QString out = QString::fromUtf8(studio.readAllStandardOutput()),
                  err = QString::fromUtf8(studio.readAllStandardError());
    qInfo("studio stdout:\n%s", qPrintable(out));
    QVERIFY2(studio.exitStatus() == QProcess::NormalExit && studio.exitCode() == 0,
             qPrintable(QString("exit %1, stderr:\n%2").arg(studio.exitCode()).arg(err)));
    QVERIFY2(!err.contains("QOpenGLWidget"), qPrintable(err));
    QVERIFY(QFile::exists(data + "/demo.png"));
    const nlohmann::json j = nlohmann::json::parse(read_bytes(data + "/stats.json").toStdString());
    QCOMPARE(j.at("view").get<std::string>(), std::string("raster"));
    for (const char* key : {"latency_median_ms", "latency_p95_ms"}) {
      const double v = j.at(key).get<double>();
      QVERIFY2(std::isfinite(v) && v > 0.0, key);
    }
    QVERIFY(j.at("latency_p95_ms").get<double>() >= j.at("latency_median_ms").get<double>());
    QVERIFY(j.at("latency_events").get<int64_t>() > 0);
    // Its parts, event by event: to the step, to the front image, to the screen. Each is a time
    // after the one before (none negative), and no part's median is over the whole's p95.
    for (const char* part : {"to_step", "to_frame", "to_screen"}) {
      const nlohmann::json& p = j.at("latency_parts").at(part);
      const double med = p.at("median_ms").get<double>(), p95 = p.at("p95_ms").get<double>();
      QVERIFY2(std::isfinite(med) && med >= 0.0 && p95 >= med, part);
      QVERIFY2(med <= j.at("latency_p95_ms").get<double>(), part);
    }

    QProcess gl;
    gl.setProcessEnvironment(env);
    gl.start(WB_STUDIO_PATH, {"--device", "cpu", "--preset", "tiny", "--data-dir", data, "--view", "gl"});
    QVERIFY(gl.waitForFinished(30000));
    QCOMPARE(gl.exitStatus(), QProcess::NormalExit);
    QCOMPARE(gl.exitCode(), 2);
    QVERIFY2(gl.readAllStandardError().contains("--view gl: no OpenGL view on the 'offscreen' platform"), "it says why");

    // The demo's measurements without the demo: an error that says so, not an idle studio.
    QProcess stats_only;
    stats_only.setProcessEnvironment(env);
    stats_only.start(WB_STUDIO_PATH, {"--device", "cpu", "--preset", "tiny", "--data-dir", data, "--demo-stats",
                                      data + "/alone.json"});
    QVERIFY2(stats_only.waitForFinished(30000), "answered within 30 s");
    QCOMPARE(stats_only.exitCode(), 2);
    QVERIFY2(stats_only.readAllStandardError().contains("--demo-stats needs --demo-screenshot"), "it says why");
    QVERIFY(!QFile::exists(data + "/alone.json"));
  }

  /// The status bar's advice when the simulation falls behind: the lighter preset of the most
  /// detail whose estimated real-time factor reaches 1, or none.
  void lighterPresetThatKeepsUp() {
    const auto samples = [](const QualityPreset& p) { return int64_t(p.bristles) * p.samples_per_bristle; };
    const QualityPreset cpu = QualityPreset::cpu(), gpu = QualityPreset::gpu(), tiny = QualityPreset::tiny();
    const QualityPreset fast = QualityPreset::fast();
    // The CPU preset at a third of real time (docs/STUDIO.md): the fast preset costs about a third
    // of it and has more detail than tiny; at a quarter only tiny keeps up; at a twentieth none.
    auto p = lighter_preset_that_keeps_up(samples(cpu), cpu.window(), 0.36);
    QVERIFY(p && p->id == "fast");
    p = lighter_preset_that_keeps_up(samples(cpu), cpu.window(), 0.26);
    QVERIFY(p && p->id == "tiny");
    QVERIFY(!lighter_preset_that_keeps_up(samples(cpu), cpu.window(), 0.05));
    QVERIFY(!lighter_preset_that_keeps_up(samples(fast), fast.window(), 0.5));
    // The paper's preset at half real time: the CPU preset keeps up, and has more detail than tiny.
    p = lighter_preset_that_keeps_up(samples(gpu), gpu.window(), 0.5);
    QVERIFY(p && p->id == "cpu");
    QVERIFY(!lighter_preset_that_keeps_up(samples(tiny), tiny.window(), 0.5));  // none is lighter
  }

  /// Every preset is named by its --preset name, its brush has the samples the brush model needs
  /// (the brush panel would otherwise raise them at the first change), and its window fits its canvas.
  void presetsAreWhatTheyName() {
    for (const QualityPreset& p : {QualityPreset::gpu(), QualityPreset::cpu(), QualityPreset::fast(), QualityPreset::tiny()}) {
      QCOMPARE(QualityPreset::from_name(p.id, Device(DeviceType::CPU)).name, p.name);
      QVERIFY2(p.samples_per_bristle >= samples_needed(p.start_brush()), p.id.c_str());
      QVERIFY(p.window().x <= p.canvas_width && p.window().y <= p.canvas_height && p.window().z <= p.canvas_depth);
    }
    QVERIFY_THROWS_EXCEPTION(wb::Error, QualityPreset::from_name("laptop", Device(DeviceType::CPU)));
    // auto: the GPU preset on a GPU; on the CPU, fast below 8 threads (two cores cannot keep up
    // with the CPU preset), the CPU preset from 8.
    QCOMPARE(QualityPreset::for_device(Device(DeviceType::CUDA), 2).id, std::string("gpu"));
    QCOMPARE(QualityPreset::for_device(Device(DeviceType::CPU), 2).id, std::string("fast"));
    QCOMPARE(QualityPreset::for_device(Device(DeviceType::CPU), 8).id, std::string("cpu"));
  }

  /// The demo's median and 95th-percentile step come from the steps' bins, counted since a copy.
  void stepTimesQuantiles() {
    StepTimes t;
    for (int ms = 1; ms <= 40; ++ms) t.add(1000.0);  // before the copy: not counted
    const StepTimes before = t;
    QCOMPARE(t.quantile_since(before, 0.5), 0.0);
    for (int ms = 1; ms <= 100; ++ms) t.add(double(ms) - 0.1);
    QCOMPARE(t.quantile_since(before, 0.5), 50.0);   // the 50th step, 49.9 ms, in the bin up to 50
    QCOMPARE(t.quantile_since(before, 0.95), 95.0);
    t.add(1000.0);  // past the bins: the last one
    QCOMPARE(t.quantile_since(before, 1.0), StepTimes::kBins * StepTimes::kBinMs);
  }

  void brushPanelRangesAreTheBrushTable() {
    // Every number the brush panel edits is a brush field, with the range the brush files and
    // their validation use (brush_field_ranges): a preset the reader accepts is never clamped.
    const auto spins = w_->brush_panel()->findChildren<QAbstractSpinBox*>();
    QVERIFY(spins.size() >= 5);
    for (QAbstractSpinBox* s : spins) {
      const std::string key = s->objectName().toStdString();
      QVERIFY2(!key.empty(), "a brush panel field without a brush-table key");
      const BrushFieldRange& f = brush_field(key);
      double lo = 0, hi = 0;
      if (auto* d = qobject_cast<QDoubleSpinBox*>(s)) lo = d->minimum(), hi = d->maximum();
      else if (auto* i = qobject_cast<QSpinBox*>(s)) lo = i->minimum(), hi = i->maximum();
      else QFAIL("unknown spin box");
      QVERIFY2(lo == f.min && hi == f.max, key.c_str());
    }
    // beta_B: the file format allows up to 1 (Newtonian), and so does the panel.
    const BrushSpec before = w_->brush_panel()->brush();
    BrushSpec b = before;
    b.beta_B = 0.5f;
    w_->brush_panel()->set_brush(b);
    QCOMPARE(w_->brush_panel()->brush().beta_B, 0.5f);
    w_->brush_panel()->set_brush(before);
  }

  void tabletEventsCarryPressureTiltRotation() {
    PenInput got;
    bool seen = false;
    auto c = connect(w_->view(), &CanvasView::penPress, this, [&](PenInput p, double) {
      got = p;
      seen = true;
    });
    std::vector<ScriptPoint> pts{{QPointF(50, 40), 0.64f, 20.f, -10.f, 30.f}};
    tablet_stroke(w_->view(), pts, 5);
    disconnect(c);
    QVERIFY(seen);
    QCOMPARE(got.pressure, 0.64f);  // pressure curve exponent 1
    QVERIFY(std::fabs(got.tilt_x - 20.f) < 1e-3f && std::fabs(got.tilt_y + 10.f) < 1e-3f);
    QVERIFY(std::fabs(got.twist - 30.f) < 1e-3f);
    QVERIFY(std::fabs(got.x - 50.f) < 0.5f && std::fabs(got.y - 40.f) < 0.5f);
    w_->settle();
    w_->undo_stack()->clear();
  }

  /// The session clock repeats a held pen's sample only after a silence longer than a moving
  /// pen's gaps: a pen whose samples reach the UI 12 to 28 ms apart (16 ms and the UI's stalls),
  /// with the hold timer firing every 8 ms, moves on every sample and never holds; held still,
  /// it is repeated. Samples are timed as they happened: a burst the UI takes late keeps its
  /// spacing.
  void penClockTimesSamplesAsTheyHappenedAndRepeatsAHeldPen() {
    PenClock clock(400, 300);
    std::vector<PenSample> line;
    auto add = [&](const ClockOutput& o) { line.insert(line.end(), o.samples.begin(), o.samples.end()); };
    double now = 100.0, next_hold = now;
    add(clock.press(PenInput{50.f, 50.f, 0.5f}, now, now));
    const size_t first_move = line.size();
    uint32_t jitter = 12345u;
    for (int i = 1; i <= 60; ++i) {
      jitter = jitter * 1664525u + 1013904223u;
      const double arrival = now + 0.012 + 0.016 * double(jitter >> 8) / double(1u << 24);
      for (; next_hold < arrival; next_hold += 0.008) add(clock.hold(next_hold));
      now = arrival;
      add(clock.move(PenInput{50.f + 4.f * float(i), 50.f, 0.5f}, now, now));
    }
    QCOMPARE(line.size(), first_move + 60);  // one sample a move, no repeat between them
    for (size_t k = first_move; k < line.size(); ++k) QVERIFY(line[k].x > line[k - 1].x);
    // Held still: repeated once the silence passes kHoldAfter, then a step apart.
    for (; next_hold < now + 0.5; next_hold += 0.008) add(clock.hold(next_hold));
    const size_t held = line.size() - (first_move + 60);
    QVERIFY2(held >= 20 && held <= 27, std::to_string(held).c_str());
    QCOMPARE(line.back().x, line[first_move + 59].x);
    QVERIFY(line[first_move + 60].t - line[first_move + 59].t >= kHoldAfter - 0.01);
    for (size_t k = first_move + 61; k < line.size(); ++k)
      QVERIFY(line[k].t - line[k - 1].t >= kStepDt - kTimeQuantum);
    const double last_down = line.back().t;
    add(clock.release(PenInput{290.f, 50.f, 0.5f}, now + 0.5));
    // The release holds the lifted pen where it was for the gap but the next press's lead: a
    // step-aligned sample the simulation runs to while the painter moves the pen.
    QVERIFY(!line.back().down && line.back().x == 290.f);
    const double held_to = line.back().t;
    QVERIFY2(held_to >= last_down + kLiftGap + kStrokeGap - kPressLead, std::to_string(held_to - last_down).c_str());
    QCOMPARE(std::fmod(held_to, kStepDt), 0.0);
    // A stroke whose samples, 16 ms apart, the UI takes in bursts of four 50 ms late.
    const double t0 = now + 1.0;
    const size_t second = line.size();
    add(clock.press(PenInput{50.f, 80.f, 0.5f}, t0, t0));
    const size_t touch = line.size() - 1;
    // The press adds its lead only, far from the last stroke: two steps of travel, lifted, to
    // a hover over the new spot, then the descent. The whole pause is the fixed gap.
    QVERIFY(!line[touch - 1].down && line[touch - 1].x == 50.f && line[touch].down);
    QCOMPARE(line[touch - 1].t, held_to + kTravel);
    QCOMPARE(line[touch].t, held_to + kPressLead);
    QVERIFY(line[touch].t - last_down >= kLiftGap + kStrokeGap);
    for (int i = 1; i <= 16; ++i) {
      const double t = t0 + 0.016 * i, arrival = t0 + 0.064 * ((i + 3) / 4) + 0.05;
      add(clock.move(PenInput{50.f + 4.f * float(i), 80.f, 0.5f}, t, arrival));
    }
    QCOMPARE(line.size(), second + 2 + 16);
    for (size_t k = touch + 1; k < line.size(); ++k)
      QVERIFY2(std::fabs((line[k].t - line[k - 1].t) - 0.016) <= kTimeQuantum + 1e-9,
               std::to_string(line[k].t - line[k - 1].t).c_str());
  }

  /// A new blank canvas, with liquid particles (the hybrid paint) or grid-only paint
  /// (SimConfig::particles = false, the paper's Fig. 7a/c).
  void grid_only_canvas(bool grid_only) {
    on_sim(*w_, [grid_only](SimThread& s) {
      SimConfig c = s.config();
      c.particles = !grid_only;
      s.rebuild(c, false);
      return 0;
    });
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
  }

  void paintUnderPathOnly() {
    grid_only_canvas(false);
    const float y0 = 60.f, x0 = 30.f, x1 = 130.f;
    stroke(y0, 0.8f, x0, x1);
    const std::vector<float> col = column_density(*w_);
    double near = 0, far = 0;
    int bx0 = kW, by0 = kH, bx1 = -1, by1 = -1;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const float v = col[size_t(y) * kW + x];
        if (v <= 0.f) continue;
        // Within the brush's reach of the path (a segment from (x0, y0) to (x1, y0)).
        const float dx = std::max({x0 - (x + 0.5f), (x + 0.5f) - x1, 0.f}), dy = (y + 0.5f) - y0;
        (std::sqrt(dx * dx + dy * dy) <= float(reach_) ? near : far) += v;
        bx0 = std::min(bx0, x), by0 = std::min(by0, y), bx1 = std::max(bx1, x), by1 = std::max(by1, y);
      }
    qInfo("paint within %d cells of the path %.2f, farther %.3g (cell volumes); painted box x %d..%d, y %d..%d",
          reach_, near, far, bx0, bx1, by0, by1);
    QVERIFY2(near > 5.0, "the stroke left paint under its path");
    // Beyond the reach only what a few particles flicked off at landing or lift-off carry:
    // measured 0 to 0.055 cell volumes over runs (up to 1e-4 of the stroke), in flecks. Less
    // than half a cell's paint in all: a few specks of film at most hundredths of a cell thick,
    // which the renderer draws translucent (docs/RENDERING.md, "Films").
    QVERIFY2(far < 0.5, "no visible paint anywhere else");
    // The mark runs from the start of the path to its end (within a few cells).
    QVERIFY2(bx0 <= int(x0) + 4 && bx1 >= int(x1) - 4, "paint from the start of the path to its end");
    QVERIFY2(by0 <= int(y0) && by1 >= int(y0), "the mark lies across the path");
  }

  void pressureChangesWidth() {
    grid_only_canvas(false);
    // Both strokes start with the same load: a clean brush dipped in the same well.
    const PaintLoad paint = w_->paint_panel()->current_paint();
    w_->clean_brush();
    w_->dip(paint);
    stroke(30.f, 0.15f);
    w_->clean_brush();
    w_->dip(paint);
    stroke(85.f, 0.95f);
    const std::vector<float> col = column_density(*w_);
    // The widest column of each mark: where the brush is set down and the bristles splay
    // (along the drag the contact of this small brush comes and goes, with either press).
    int light = 0, heavy = 0;
    for (int x = 0; x < kW; ++x) {
      light = std::max(light, painted_width(col, kW, kH, x, 0, 57));
      heavy = std::max(heavy, painted_width(col, kW, kH, x, 58, kH));
    }
    qInfo("widest painted column: light press (0.15) %d cells, heavy press (0.95) %d cells", light, heavy);
    QVERIFY2(light > 0, "a light press paints");
    QVERIFY2(heavy >= light + 3, "a harder press paints a wider stroke");
  }

  void canvasTextureCatchesADryBrush() {
    // A lightly loaded brush dragged lightly across linen in the studio (a slanted stroke, across
    // the weave). The property is measured on the session's own recording, which carries the
    // ground, with the stroke's timing as the script meant it: `wetbrush replay` of it, and of
    // the same recording without its ground (a smooth board), paint the same pen input on both:
    // on linen the hollows take less paint than the board takes there, and the paint lies on the
    // threads' crowns (docs/STUDIO.md "Canvas texture").
    PaintLoad dry = w_->paint_panel()->current_paint();
    dry.load = 0.3f;
    const QColor paper(235, 228, 210);
    const CanvasGround linen = CanvasGround::of(Weave::Linen);
    const QPointF a(30.f, 45.f), b(130.f, 75.f);
    w_->new_canvas(kW, kH, paper, linen);
    w_->settle();
    w_->clean_brush();
    w_->dip(dry);
    tablet_stroke(w_->view(), line_points(a, b, 48, 0.1f), 20);
    w_->settle();
    const QString rec = dir_->path() + "/linen-session.json";
    QVERIFY(w_->save_recording(rec));
    nlohmann::json session = nlohmann::json::parse(read_bytes(rec).toStdString());
    QVERIFY2(session["canvas"].contains("ground"), "the recording carries the ground");
    {
      // The pen as the script moved it, whatever the machine's load: the samples carry the
      // script's timestamps, but a UI stalled past kHoldAfter still adds holds (repeats of the last
      // sample) where a dry brush lays more. The stroke's samples are re-timed 20/1024 s apart,
      // its holds dropped, and what follows it moved by the same amount.
      const double dt = 20.0 / 1024.0;
      nlohmann::json kept = nlohmann::json::array();
      int down = 0;
      double shift = 0.0, t0 = 0.0;
      for (nlohmann::json smp : session["samples"]) {
        if (smp.value("down", true) && shift == 0.0) {
          const nlohmann::json& last = kept.empty() ? smp : kept.back();
          if (down > 0 && last["x"] == smp["x"] && last["y"] == smp["y"] && last["pressure"] == smp["pressure"])
            continue;
          if (down == 0) t0 = smp["t"].get<double>();
          smp["t"] = t0 + dt * down++;
        } else if (down > 0) {
          if (shift == 0.0) shift = kept.back()["t"].get<double>() + kLiftGap - smp["t"].get<double>();
          smp["t"] = smp["t"].get<double>() + shift;
        }
        kept.push_back(smp);
      }
      QVERIFY2(down >= 40, "the stroke's samples");
      session["samples"] = kept;
      if (session.contains("events"))
        for (nlohmann::json& e : session["events"])
          if (e["t"].get<double>() > t0) e["t"] = e["t"].get<double>() + shift;
    }
    const auto write_json = [](const QString& path, const nlohmann::json& j) {
      QFile f(path);
      return f.open(QIODevice::WriteOnly) && f.write(QByteArray::fromStdString(j.dump())) > 0;
    };
    QVERIFY(write_json(rec, session));
    session["canvas"].erase("ground");
    const QString rec_smooth = dir_->path() + "/smooth-session.json";
    QVERIFY(write_json(rec_smooth, session));
    const auto replay = [&](const QString& stroke) {
      const QString out = stroke + ".ora";
      QProcess cli;
      QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
      env.insert("OMP_NUM_THREADS", "1");
      cli.setProcessEnvironment(env);
      cli.start(WB_CLI_PATH, {"replay", stroke, "--device", "cpu", "--save", out, "--quiet"});
      const bool done = cli.waitForFinished(120000) && cli.exitStatus() == QProcess::NormalExit && cli.exitCode() == 0;
      if (!done) qWarning("%s", cli.readAllStandardError().constData());
      return done ? std::optional(load_painting(out.toStdString(), Device::parse("cpu"))) : std::nullopt;
    };
    const float nx = -float(b.y() - a.y()), ny = float(b.x() - a.x()), nl = std::hypot(nx, ny);
    const WeaveField wf = weave_field(linen, GridParams{}.cell_size, Vec3{});
    // The paint per column over linen's crowns (the top third of the relief) and hollows (the
    // bottom third), on either board: the smooth board takes paint where linen has its hollows.
    double cover[2] = {}, crowns[2] = {}, hollows[2] = {};
    for (const bool woven : {false, true}) {
      std::optional<Painting> p = replay(woven ? rec : rec_smooth);
      QVERIFY2(p.has_value(), "wetbrush replay of the session's recording");
      const std::vector<float> fresh = column_density(p->canvas, true);
      int covered = 0, columns = 0, n_crowns = 0, n_hollows = 0;
      for (int y = 0; y < kH; ++y)
        for (int x = 40; x < 120; ++x) {
          const float d = std::abs(((x + 0.5f) - float(a.x())) * nx + ((y + 0.5f) - float(a.y())) * ny) / nl;
          if (d > 4.f) continue;  // the band under the brush
          const float v = fresh[size_t(y) * kW + x];
          if (d <= 2.f) covered += v > 0.05f, ++columns;  // coverage under the brush's middle
          const float h = (weave_height(wf, x + 0.5f, y + 0.5f) - wf.base) / wf.relief;
          if (h > 0.67f) crowns[woven] += v, ++n_crowns;
          if (h < 0.33f) hollows[woven] += v, ++n_hollows;
        }
      cover[woven] = double(covered) / columns;
      crowns[woven] /= std::max(n_crowns, 1);
      hollows[woven] /= std::max(n_hollows, 1);
    }
    qInfo("dry brush (the session replayed): covers %.2f of the track on a smooth board, %.2f on linen; cells per "
          "column over linen's crowns and hollows: %.3f and %.3f on the smooth board, %.3f and %.3f on linen",
          cover[0], cover[1], crowns[0], hollows[0], crowns[1], hollows[1]);
    QVERIFY2(cover[0] > 0.25, "the light brush paints the smooth board");
    // Where the light brush's paint joins into a film, surface tension draws part of it from the
    // crowns into the hollows (docs/GRID.md "Surface tension"): 0.70 of the board's there, the
    // crowns 1.5 times the hollows (docs/STUDIO.md "Canvas texture").
    QVERIFY2(hollows[1] < 0.75 * hollows[0], "linen's hollows take less paint than the smooth board takes there");
    QVERIFY2(crowns[1] > 1.4 * hollows[1], "the paint lies on the threads' crowns");
    // The ground is the painting's: saved, reopened, and in the recording of the session.
    const QString path = dir_->path() + "/linen.ora";
    QVERIFY(w_->save_to(path, true));
    w_->new_canvas(kW, kH, paper);
    QVERIFY(w_->open_from(path));
    w_->settle();
    const auto ground = on_sim(*w_, [](SimThread& s) { return s.session().ground(); });
    QVERIFY2(ground && *ground == linen, "the painting reopens on its linen");
    const Stroke reopened = on_sim(*w_, [](SimThread& s) { return s.recording(); });
    QVERIFY2(reopened.ground && *reopened.ground == linen, "a recording from the reopened painting keeps the ground");
    const std::vector<float> all = column_density(*w_);
    const float crown = weave_height(weave_field(linen, GridParams{}.cell_size, Vec3{}), 2.5f, 2.5f);
    QVERIFY2(std::abs(all[2 * kW + 2] - crown) < 0.5f, "the weave is in the reopened volume");
    // A ground entry this build cannot read costs the recordings their ground, not the painting.
    const QString odd = dir_->path() + "/odd-ground.ora";
    TileStore blank(Device{}, CanvasDims{kW, kH, preset_.canvas_depth});
    save_painting(odd.toStdString(), blank, Image(kW, kH), {{"ground", {{"weave", "burlap"}}}});
    QVERIFY2(w_->open_from(odd), "a painting with an unreadable ground entry opens");
    w_->settle();
    QVERIFY(!on_sim(*w_, [](SimThread& s) { return s.session().ground(); }).has_value());
  }

  void paletteMixesPaintAndLoadsTheBrush() {
    // Blue and yellow put out on the palette side by side, scrubbed together with the brush, and
    // the brush, loaded from the puddle by painting through it, paints green on the canvas
    // (docs/STUDIO.md "Palette").
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
    w_->paint_panel()->set_reload_each_stroke(false);  // the brush keeps the palette's mix
    PalettePanel* pal = w_->palette();
    on_thread(*pal->sim(), [](SimThread& s) {
      s.session().clear();
      return 0;
    });
    const float pw = float(preset_.palette_width), ph = float(preset_.palette_height);
    PaintLoad blue, yellow;
    blue.ryb[0] = 0.05f, blue.ryb[1] = 0.1f, blue.ryb[2] = 0.9f;
    yellow.ryb[0] = 0.05f, yellow.ryb[1] = 0.9f, yellow.ryb[2] = 0.05f;
    pal->put_paint(QPointF(0.38 * pw, 0.5 * ph), blue);
    pal->put_paint(QPointF(0.62 * pw, 0.5 * ph), yellow);
    w_->clean_brush();
    w_->settle();
    QVERIFY(!w_->brush_on_palette());
    // Back and forth through both dabs.
    for (int k = 0; k < 4; ++k) {
      const double y = 0.5 * ph + (k % 2 ? 2.0 : -2.0);
      const QPointF a(0.2 * pw, y), b(0.8 * pw, y);
      tablet_stroke(pal->view(), line_points(k % 2 ? b : a, k % 2 ? a : b, 40, 0.6f), 20);
    }
    w_->settle();
    QVERIFY2(w_->brush_on_palette(), "painting on the palette carries the brush there");
    const auto [mixed, on_palette] = on_thread(*pal->sim(), [](SimThread& s) {
      TileStore c = s.sim().settled_canvas_copy(Device{});
      return wet_pigment(c);
    });
    const BrushPicture loaded = on_thread(*pal->sim(), [](SimThread& s) { return s.sim().brush_picture(); });
    qInfo("palette: %.1f cells of paint, mean RYB %.2f %.2f %.2f; the brush: RYB %.2f %.2f %.2f, fill %.2f", on_palette,
          mixed.x, mixed.y, mixed.z, loaded.mean_ryb.x, loaded.mean_ryb.y, loaded.mean_ryb.z, loaded.amount);
    QVERIFY2(loaded.amount > 0.05f, "the brush picked paint up on the palette");
    QVERIFY2(loaded.mean_ryb.y > 0.2f && loaded.mean_ryb.z > 0.2f, "the brush holds both the blue and the yellow");
    // Painting on the canvas carries the brush back with its paint.
    stroke(60.f, 0.6f);
    QVERIFY(!w_->brush_on_palette());
    const auto [painted, on_canvas] = on_sim(*w_, [](SimThread& s) {
      TileStore c = s.sim().settled_canvas_copy(Device{});
      return wet_pigment(c);
    });
    const Vec3 rgb = ryb_to_rgb(painted);
    qInfo("canvas: %.1f cells of paint, mean RYB %.2f %.2f %.2f, RGB %.2f %.2f %.2f", on_canvas, painted.x, painted.y,
          painted.z, rgb.x, rgb.y, rgb.z);
    QVERIFY2(on_canvas > 1.0, "the brush loaded on the palette paints the canvas");
    QVERIFY2(painted.y > 0.2f && painted.z > 0.2f && painted.x < 0.2f, "green paint: yellow and blue, little red");
    QVERIFY2(rgb.y > rgb.x && rgb.y > rgb.z, "it looks green");
    // The palette is saved with the painting and comes back on open.
    const auto palette_volume = [&] {
      return on_thread(*pal->sim(), [](SimThread& s) {
        TileStore c = s.sim().settled_canvas_copy(Device{});
        return canonical_volume(c, false);
      });
    };
    const std::vector<uint8_t> saved = palette_volume();
    const QString path = dir_->path() + "/palette.ora";
    QVERIFY(w_->save_to(path, true));
    pal->put_paint(QPointF(0.5 * pw, 0.2 * ph), blue);  // the palette changes after the save
    w_->settle();
    QVERIFY(palette_volume() != saved);
    QVERIFY(w_->open_from(path));
    w_->settle();
    QVERIFY2(palette_volume() == saved, "the painting reopens with its palette");
  }

  void eyedropperPicksThePaintedPigment() {
    grid_only_canvas(false);
    PaintPanel* pp = w_->paint_panel();
    // Paint with well 0 set to a blue; then select well 1 and pick the colour off the stroke.
    const std::array<float, 3> blue{0.05f, 0.1f, 0.9f};
    pp->set_well_ryb(0, blue);
    QTest::mouseClick(pp->findChildren<QToolButton*>()[0], Qt::LeftButton);
    QCOMPARE(pp->current_well(), 0);
    w_->clean_brush();
    w_->dip(pp->current_paint());
    stroke(60.f, 0.8f);
    // The stroke's thickest column, near its middle.
    const std::vector<float> col = column_density(*w_);
    int bx = -1, by = -1;
    float best = 0.f;
    for (int y = 40; y < 80; ++y)
      for (int x = 60; x < 100; ++x)
        if (col[size_t(y) * kW + x] > best) best = col[size_t(y) * kW + x], bx = x, by = y;
    QVERIFY2(best > 1.f, "the stroke left thick paint");
    // What the renderer shows there (unlit), and the pigment behind it.
    const Vec3 albedo = on_sim(*w_, [&](SimThread& s) {
      const FloatImage a = s.session().albedo();
      return Vec3(a.at(bx, by, 0), a.at(bx, by, 1), a.at(bx, by, 2));
    });
    QTest::mouseClick(pp->findChildren<QToolButton*>()[1], Qt::LeftButton);
    QCOMPARE(pp->current_well(), 1);
    const std::array<float, 3> before = pp->well_ryb(1);
    QTest::mouseClick(w_->view(), Qt::LeftButton, Qt::AltModifier, w_->view()->to_widget(QPointF(bx + 0.5, by + 0.5)).toPoint());
    QCoreApplication::processEvents();
    const std::array<float, 3> got = pp->well_ryb(1);
    const Vec3 shown = ryb_to_rgb(Vec3(got[0], got[1], got[2]));
    qInfo("picked at (%d, %d): RYB %.3f %.3f %.3f (painted %.2f %.2f %.2f); renders %.3f %.3f %.3f, shown %.3f %.3f %.3f",
          bx, by, got[0], got[1], got[2], blue[0], blue[1], blue[2], shown.x, shown.y, shown.z, albedo.x, albedo.y,
          albedo.z);
    QVERIFY2(got != before, "Alt+click put a colour in the selected well");
    QVERIFY2(pp->well_ryb(0) == blue, "the other wells keep theirs");
    // The picked pigment renders as the canvas shows there, and thick paint is the brush's paint.
    QVERIFY2(length(shown - albedo) < 0.02f, "the picked pigment renders the colour shown");
    QVERIFY2(length(Vec3(got[0], got[1], got[2]) - Vec3(blue[0], blue[1], blue[2])) < 0.1f, "thick paint: the painted pigment");
    // Bare canvas has no paint to pick: the well stays as it is.
    QVERIFY(!w_->pick_color(QPointF(5.5, 5.5)).has_value());
    QVERIFY2(pp->well_ryb(1) == got, "picking bare canvas leaves the well");
  }

  void easelTiltGoesIntoTheSimulationAndTheRecording() {
    // Canvas > Easel tilt: the canvas's simulator turns its gravity (grid, particles, bristles)
    // with the canvas, and the recording keeps the tilt, so a replay paints on the same easel.
    grid_only_canvas(false);
    w_->set_tilt(90.f);
    w_->settle();
    const SimConfig c = on_sim(*w_, [](SimThread& s) { return s.sim().config(); });
    QCOMPARE(c.params.grid.tilt, 90.f);
    QVERIFY(c.params.particles.gravity.y > 49000.f && std::fabs(c.params.particles.gravity.z) < 1.f);
    const float palette_tilt = on_thread(*w_->palette()->sim(), [](SimThread& s) { return s.sim().config().params.grid.tilt; });
    QCOMPARE(palette_tilt, 0.f);
    stroke(40.f, 0.6f);
    const QString rec = dir_->path() + "/easel.json";
    QVERIFY(w_->save_recording(rec));
    const Stroke st = load_stroke(rec.toStdString());
    QVERIFY(st.tilt.has_value());
    QCOMPARE(*st.tilt, 90.f);
    w_->set_tilt(0.f);
    w_->settle();
    QCOMPARE(on_sim(*w_, [](SimThread& s) { return s.sim().config().params.grid.tilt; }), 0.f);
  }

  void easelPaintRunsOnWhileThePenIsAway() {
    // On an easel oily paint keeps running after the pen lifts: the time line goes on a step at a
    // time while the simulation has caught up and its paint still runs (PenClock::air,
    // Simulator::paint_running: faster than 2 mm/s), and stops when it runs no more, whatever the tilt.
    const auto centre_y = [&] {
      return on_sim(*w_, [](SimThread& s) {
        TileStore c = s.sim().settled_canvas_copy(Device{});
        const CanvasDims d = c.dims();
        double m = 0.0, my = 0.0;
        for (int id : c.allocated_tile_ids()) {
          const TileData t = c.read_tile(id);
          for (int z = 0; z < d.depth; ++z)
            for (int ly = 0; ly < kTileSize; ++ly)
              for (int lx = 0; lx < kTileSize; ++lx) {
                const float r = t.density[size_t((z * kTileSize + ly) * kTileSize + lx)];
                m += r, my += r * (t.tile_y * kTileSize + ly + 0.5);
              }
        }
        return m > 0.0 ? my / m : 0.0;
      });
    };
    // Waits with the pen away for `ms`, or until `steps` more steps are done or the paint runs no
    // more (a loaded machine paces the steps slower than the wall clock).
    const auto away = [&](int ms, int64_t steps, bool until_still) {
      const int64_t s0 = w_->sim()->status().steps;
      QElapsedTimer t;
      t.start();
      while (t.elapsed() < ms && !(steps > 0 && w_->sim()->status().steps - s0 >= steps) &&
             !(until_still && !w_->sim()->paint_running() && w_->sim()->is_idle())) {
        QCoreApplication::processEvents(QEventLoop::AllEvents, 5);
        QThread::usleep(500);
      }
      w_->settle();
    };
    const auto oily_stroke = [&](float tilt) {
      grid_only_canvas(false);
      w_->set_tilt(tilt);
      w_->paint_panel()->set_reload_each_stroke(false);
      w_->clean_brush();
      PaintLoad oily = w_->paint_panel()->current_paint();
      oily.oil = 0.9f, oily.load = 1.f;
      w_->dip(oily);
      stroke(40.f, 1.f, 70.f, 90.f);  // slow and pressed: a thick bead of oily paint
    };
    // Upright: the bead runs on down the canvas while the pen is away, a second and a half of
    // steps (at most the wall clock's pace).
    oily_stroke(90.f);
    const double y0 = centre_y();
    const int64_t s0 = w_->sim()->status().steps;
    QElapsedTimer wall;
    wall.start();
    away(30000, 96, false);
    const double y1 = centre_y();
    const int64_t s1 = w_->sim()->status().steps;
    qInfo("upright: the paint's centre at y %.2f after the stroke, %.2f after %lld steps away (%.1f s)", y0, y1,
          (long long)(s1 - s0), wall.elapsed() / 1000.0);
    QVERIFY2(s1 - s0 >= 96, "the running paint is simulated while the pen is away");
    QVERIFY2(wall.elapsed() >= 1400, "no faster than the wall clock");
    QVERIFY2(y1 - y0 > 0.5, "and runs down the easel");
    // Flat: the oily bead spreads for a while, then runs no more, and nothing more is simulated.
    oily_stroke(0.f);
    const int64_t s_flat = w_->sim()->status().steps;
    away(30000, 0, true);
    QVERIFY2(!w_->sim()->paint_running(), "the spreading bead stops running");
    const double y2 = centre_y();
    const int64_t s2 = w_->sim()->status().steps;
    away(500, 0, false);
    qInfo("flat: running no more after %lld steps away; %lld steps in the next 0.5 s", (long long)(s2 - s_flat),
          (long long)(w_->sim()->status().steps - s2));
    QCOMPARE(w_->sim()->status().steps, s2);
    QVERIFY(std::fabs(centre_y() - y2) < 1e-6);
    w_->set_tilt(0.f);
    w_->paint_panel()->set_reload_each_stroke(true);
    w_->settle();
  }

  void reloadEachStrokeLoadsTheSelectedWell() {
    // On (the default): every stroke paints the selected well's colour, whatever the brush held;
    // off: the brush keeps its paint from stroke to stroke. The choice is kept in studio.ini.
    grid_only_canvas(false);
    PaintPanel* pp = w_->paint_panel();
    QVERIFY(pp->reload_each_stroke());
    const std::array<float, 3> blue{0.05f, 0.1f, 0.9f}, yellow{0.05f, 0.9f, 0.05f}, red{0.9f, 0.1f, 0.05f};
    const auto wet = [&] {
      return on_sim(*w_, [](SimThread& s) {
        TileStore c = s.sim().settled_canvas_copy(Device{});
        return wet_pigment(c);
      });
    };
    const auto near = [](Vec3 a, const std::array<float, 3>& b) {
      return std::max({std::fabs(a.x - b[0]), std::fabs(a.y - b[1]), std::fabs(a.z - b[2])});
    };
    pp->set_well_ryb(pp->current_well(), blue);
    stroke(30.f, 0.6f);
    const auto [first, m1] = wet();
    w_->dry_canvas();
    w_->settle();
    pp->set_well_ryb(pp->current_well(), yellow);
    stroke(60.f, 0.6f);
    const auto [second, m2] = wet();
    w_->dry_canvas();
    w_->settle();
    pp->set_reload_each_stroke(false);
    pp->set_well_ryb(pp->current_well(), red);
    stroke(90.f, 0.6f);
    const auto [third, m3] = wet();
    qInfo("reload on: blue stroke RYB %.2f %.2f %.2f (%.1f cells), yellow %.2f %.2f %.2f (%.1f); off, red well: "
          "%.2f %.2f %.2f (%.1f)",
          first.x, first.y, first.z, m1, second.x, second.y, second.z, m2, third.x, third.y, third.z, m3);
    QVERIFY(m1 > 1.0 && m2 > 1.0 && m3 > 1.0);
    QVERIFY2(near(first, blue) < 0.05f, "the first stroke paints the well");
    QVERIFY2(near(second, yellow) < 0.05f, "reloaded: the yellow well, none of the blue");
    QVERIFY2(near(third, yellow) < 0.1f, "not reloaded: the brush's yellow, not the red well");
    QVERIFY(!QSettings(dir_->path() + "/data/studio.ini", QSettings::IniFormat).value("reload_each_stroke").toBool());
  }

  void brushPreviewShowsTheBrushAndItsPaint() {
    grid_only_canvas(false);
    w_->paint_panel()->set_reload_each_stroke(false);  // the dip's fill, not the well's
    BrushPreview* bp = w_->brush_preview();
    const auto wait_for = [&](const std::function<bool()>& ok) {
      QElapsedTimer t;
      t.start();
      while (!ok() && t.elapsed() < 5000) {
        QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
        QThread::msleep(5);
      }
      return ok();
    };
    w_->clean_brush();
    w_->settle();
    QVERIFY2(wait_for([&] { return bp->picture().bristles == brush_.bristles && bp->picture().amount == 0.f; }),
             "a clean brush: all bristles, no paint");
    PaintLoad blue = w_->paint_panel()->current_paint();
    blue.ryb[0] = 0.05f;
    blue.ryb[1] = 0.1f;
    blue.ryb[2] = 0.9f;
    blue.load = 0.7f;
    w_->dip(blue);
    // The dip is applied with the next step: a short hover makes one.
    tablet_stroke(w_->view(), line_points(QPointF(20, 20), QPointF(22, 20), 3, 0.f), 20);
    w_->settle();
    QVERIFY2(wait_for([&] { return std::abs(bp->picture().amount - 0.7f) < 0.02f; }), "the dip fills the preview");
    const Vec3 c = bp->picture().mean_ryb;
    qInfo("preview after the dip: amount %.3f, RYB %.3f %.3f %.3f", bp->picture().amount, c.x, c.y, c.z);
    QVERIFY(std::abs(c.z - 0.9f) < 0.02f && std::abs(c.x - 0.05f) < 0.02f);
    // While painting, pressed bristles touch the canvas; afterwards the brush holds less.
    int touching = 0;
    const auto conn = connect(w_->sim(), &SimThread::frameReady, this, [&] { touching = std::max(touching, bp->touching()); });
    stroke(60.f, 0.8f);
    disconnect(conn);
    QVERIFY2(wait_for([&] { return bp->picture().amount < 0.69f; }), "painting takes paint off the brush");
    qInfo("preview: at most %d bristle vertices touching while painting; amount after %.3f", touching,
          bp->picture().amount);
    QVERIFY2(touching > 0, "pressed bristles touch the canvas in the preview");
    const QImage shot = bp->grab().toImage();
    QVERIFY(!shot.isNull());
  }

  void brushChangeAndOpenReadNoCanvasBack() {
    grid_only_canvas(false);
    stroke(30.f, 0.8f, 20.f, 140.f);
    stroke(60.f, 0.8f);
    stroke(90.f, 0.8f, 20.f, 140.f);
    // The canvas goes to the new simulator on the device: the host reads a brush change makes
    // (the settle's counts, the books, the first render) do not grow with the painting.
    const auto [tiles, reads, volume_before, volume_after] = on_sim(*w_, [](SimThread& s) {
      const int64_t tiles = s.sim().canvas().allocated_tiles();
      const double before = s.sim().settled_canvas_copy(Device{}).total_density();
      const int64_t r0 = mem::host_reads();
      s.rebuild(s.config(), true);
      const int64_t reads = mem::host_reads() - r0;
      return std::tuple<int64_t, int64_t, double, double>(tiles, reads, before, s.sim().canvas().total_density());
    });
    qInfo("brush change with %lld painted tiles: %lld host reads; paint %.4f -> %.4f cell volumes", (long long)tiles,
          (long long)reads, volume_before, volume_after);
    QVERIFY2(tiles > 40, "a painting of many tiles");
    QVERIFY2(reads < tiles, "the canvas is not read back tile by tile (6 reads a tile before)");
    QVERIFY2(std::abs(volume_after - volume_before) <= 1e-6 * volume_before, "the paint, in flight too, is kept");
  }

  void obliqueViewAndRakingLight() {
    grid_only_canvas(false);
    ViewPanel* vp = w_->view_panel();
    // Right-button drag on the canvas moves the light: 100 px left turns it 50 degrees, 40 px
    // down lowers it 10 degrees.
    vp->set_light(200.f, 50.f, true);
    const QPoint a = w_->view()->rect().center();
    QTest::mousePress(w_->view(), Qt::RightButton, Qt::NoModifier, a);
    QTest::mouseMove(w_->view(), a + QPoint(-100, 40));
    {
      QMouseEvent release(QEvent::MouseButtonRelease, QPointF(a + QPoint(-100, 40)), w_->view()->mapToGlobal(QPointF(a + QPoint(-100, 40))),
                          Qt::RightButton, Qt::NoButton, Qt::NoModifier);
      QApplication::sendEvent(w_->view(), &release);
    }
    qInfo("light after the drag: azimuth %.0f, elevation %.0f", vp->azimuth(), vp->elevation());
    QCOMPARE(vp->azimuth(), 250.f);
    QCOMPARE(vp->elevation(), 40.f);
    // The oblique view appears when asked for and follows the canvas and the light.
    const auto wait_render = [&](int after) {
      QElapsedTimer t;
      t.start();
      while (w_->oblique_renders() <= after && t.elapsed() < 60000) {
        QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
        QThread::msleep(5);
      }
      return w_->oblique_renders() > after;
    };
    const auto differ = [](const QImage& x, const QImage& y) {
      int64_t d = 0;
      for (int j = 0; j < x.height(); ++j)
        for (int i = 0; i < x.width(); ++i) d += std::abs(qGray(x.pixel(i, j)) - qGray(y.pixel(i, j)));
      return double(d) / double(x.width() * x.height());
    };
    int n = w_->oblique_renders();
    vp->set_oblique(true);
    QVERIFY2(wait_render(n), "turning the oblique view on renders it");
    const QImage blank = w_->oblique_image();
    QVERIFY(!blank.isNull());
    QCOMPARE(blank.width(), kW);  // the whole canvas, one pixel per cell for a canvas this small
    QVERIFY2(blank.height() < kH, "seen from 30 degrees the canvas is foreshortened");
    n = w_->oblique_renders();
    stroke(60.f, 0.8f);
    QVERIFY2(wait_render(n), "a stroke refreshes the oblique view");
    const QImage painted = w_->oblique_image();
    const double stroke_change = differ(blank, painted);
    n = w_->oblique_renders();
    vp->rake();
    QCOMPARE(vp->elevation(), 12.f);
    QVERIFY2(wait_render(n), "a new light refreshes the oblique view");
    const double light_change = differ(painted, w_->oblique_image());
    qInfo("oblique view %dx%d: mean grey change %.2f after the stroke, %.2f under the raking light", painted.width(),
          painted.height(), stroke_change, light_change);
    QVERIFY2(stroke_change > 0.5, "the stroke shows in the oblique view");
    QVERIFY2(light_change > 0.5, "the raking light shows in the oblique view");
    vp->set_oblique(false);
    vp->set_light(231.f, 50.f, true);
  }

  void undoRestoresExactCanvasRedoReapplies() {
    grid_only_canvas(false);  // with particles: paint in flight at the end of a stroke
    stroke(35.f, 0.6f);
    const std::vector<uint8_t> before = volume_bytes(*w_, false);
    const int n0 = w_->undo_stack()->count();
    QCOMPARE(n0, 1);
    stroke(80.f, 0.7f, 20.f, 140.f);
    QCOMPARE(w_->undo_stack()->count(), n0 + 1);
    const std::vector<uint8_t> after = volume_bytes(*w_, false);
    QVERIFY(after != before);
    // The paint comes back exactly; its dryness keeps the drying done meanwhile
    // (TileStoreTest.PaintDriesByTheClockAndUndoKeepsTheDrying).
    w_->undo_stack()->undo();
    w_->settle();
    QVERIFY2(volume_bytes(*w_, false) == before, "undo restores the paint exactly");
    w_->undo_stack()->redo();
    w_->settle();
    QVERIFY2(volume_bytes(*w_, false) == after, "redo re-applies the stroke exactly");
    // Undo both strokes: back to the blank canvas.
    w_->undo_stack()->undo();
    w_->undo_stack()->undo();
    w_->settle();
    const std::vector<float> col = column_density(*w_);
    QVERIFY2(std::all_of(col.begin(), col.end(), [](float v) { return v == 0.f; }), "undo of every stroke leaves no paint");
    w_->undo_stack()->redo();
    w_->undo_stack()->redo();
    w_->settle();
    QVERIFY2(volume_bytes(*w_, false) == after, "redo of both strokes gives the painting back");
  }

  void aFaultMidStrokeKeepsThePaintingAsBeforeTheStroke() {
    // A device fault in the middle of a stroke (the fault hook: the n-th launch from now throws,
    // as a kernel fault or a failed allocation would): the stroke ends, the painting is as it was
    // before it, the painter is told, and painting and saving go on.
    grid_only_canvas(false);
    const int64_t l0 = on_sim(*w_, [](SimThread&) { return mem::launches(); });
    stroke(35.f, 0.6f);
    const int64_t per_stroke = on_sim(*w_, [](SimThread&) { return mem::launches(); }) - l0;
    const std::vector<uint8_t> before = volume_bytes(*w_, false);
    const int undo0 = w_->undo_stack()->count();
    QSignalSpy told(w_->sim(), &SimThread::failed);
    // Half-way through a stroke like the first (the launches the simulation thread makes).
    mem::inject_fault_after(per_stroke / 2);
    stroke(80.f, 0.7f);
    mem::inject_fault_after(0);
    qInfo("%lld launches a stroke; fault after %lld", (long long)per_stroke, (long long)(per_stroke / 2));
    QCOMPARE(told.count(), 1);
    const QString m = told.first().first().toString();
    qInfo("the painter is told: %s", qPrintable(m));
    QVERIFY2(m.contains("before it") && m.contains("save it now") && m.contains("injected fault"), qPrintable(m));
    const SimStatus st = w_->sim()->status();
    QCOMPARE(st.faults, int64_t(1));
    QVERIFY2(st.error.empty(), "the simulation goes on");
    QVERIFY2(volume_bytes(*w_, false) == before, "the painting is as it was before the stroke");
    QCOMPARE(w_->undo_stack()->count(), undo0);
    // The next stroke paints, with the well's paint, and the painting saves and opens.
    stroke(110.f, 0.7f);
    QVERIFY2(volume_bytes(*w_, false) != before, "the next stroke paints");
    QCOMPARE(w_->undo_stack()->count(), undo0 + 1);
    const QString path = dir_->path() + "/after-fault.ora";
    QVERIFY(w_->save_to(path, true));
    QVERIFY2(encode_volume(load_painting(path.toStdString(), Device::parse("cpu")).canvas) == volume_bytes(*w_),
             "the saved file holds the canvas");
  }

  void aSimulatorTooLargeForTheMemoryLimitKeepsThePainting() {
    // A brush or canvas change that the memory limit cannot hold is refused with the bytes it
    // needs, and the painting and its simulation stay as they were.
    grid_only_canvas(false);
    stroke(40.f, 0.6f);
    const std::vector<uint8_t> before = volume_bytes(*w_, false);
    const size_t held = mem::usage(false).in_use;
    mem::set_budget(false, held + (size_t(8) << 20));
    const std::string refused = on_sim(*w_, [](SimThread& s) {
      SimConfig c = s.config();
      c.window = Int3{512, 512, 64};
      try {
        s.rebuild(c, true);
      } catch (const Error& e) {
        return std::string(e.what());
      }
      return std::string();
    });
    mem::set_budget(false, 0);
    qInfo("refused: %s", refused.c_str());
    QVERIFY2(refused.find("512 x 512 x 64 cells needs about") != std::string::npos, refused.c_str());
    QVERIFY2(volume_bytes(*w_, false) == before, "the painting stays");
    stroke(90.f, 0.7f);
    QVERIFY2(volume_bytes(*w_, false) != before, "and the simulation paints on");
  }

  void saveThenOpenGivesSameVolume() {
    grid_only_canvas(false);
    stroke(50.f, 0.6f);
    const std::vector<uint8_t> now = volume_bytes(*w_);
    QVERIFY(now.size() > 0);
    const QString path = dir_->path() + "/painting.ora";
    QVERIFY(w_->save_to(path, true));
    QVERIFY(!w_->modified());
    // What the file holds is what the studio had.
    QVERIFY2(encode_volume(load_painting(path.toStdString(), Device::parse("cpu")).canvas) == now,
             "the saved file holds the canvas");
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
    QVERIFY(volume_bytes(*w_) != now);
    QVERIFY(w_->open_from(path));
    w_->settle();
    QVERIFY2(volume_bytes(*w_) == now, "save then open gives the same paint volume");
    QVERIFY(!w_->modified());
  }

  void exportGivesTheCliFilesByteForByte() {
    // File > Export and `wetbrush export` of the same painting write the same files: one writer
    // (core/io/material_maps), the normal map's +Y up the image in both.
    grid_only_canvas(false);
    stroke(50.f, 0.6f);
    const QString path = dir_->path() + "/export.ora";
    QVERIFY(w_->save_to(path, true));
    QVERIFY(w_->open_from(path));
    w_->settle();
    const QString h = dir_->path() + "/studio-height.png", n = dir_->path() + "/studio-normal.png";
    QVERIFY(w_->export_maps(h, n));
    const QString h2 = dir_->path() + "/cli-height.png", n2 = dir_->path() + "/cli-normal.png";
    QProcess cli;
    cli.start(WB_CLI_PATH, {"export", path, "--height", h2, "--normal", n2, "--device", "cpu"});
    QVERIFY(cli.waitForFinished(120000));
    QVERIFY2(cli.exitStatus() == QProcess::NormalExit && cli.exitCode() == 0, cli.readAllStandardError().constData());
    const auto bytes = [](const QString& f) {
      QFile file(f);
      return file.open(QIODevice::ReadOnly) ? file.readAll() : QByteArray();
    };
    QVERIFY(!bytes(h).isEmpty() && !bytes(n).isEmpty());
    QVERIFY2(bytes(h) == bytes(h2), "height maps differ");
    QVERIFY2(bytes(n) == bytes(n2), "normal maps differ");
  }

#if WB_WITH_MEDIA
  void fileMenuExportsReliefs() {
    // File > Export height (OpenEXR), relief (STL) and relief (glTF): each action asks for a file
    // and writes it with the core's relief writers; the files load back.
    grid_only_canvas(false);
    stroke(50.f, 0.6f);
    w_->settle();
    const QString exr = dir_->path() + "/relief.exr", stl = dir_->path() + "/relief.stl",
                  glb = dir_->path() + "/relief.glb";
    QMenu* file = nullptr;
    for (QAction* a : w_->menuBar()->actions())
      if (a->text() == "&File") file = a->menu();
    QVERIFY(file);
    for (const auto& [label, path] : {std::pair{QString("(&OpenEXR)"), exr}, std::pair{QString("(&STL)"), stl},
                                      std::pair{QString("(&glTF)"), glb}}) {
      QAction* action = nullptr;
      for (QAction* a : file->actions())
        if (a->text().contains(label)) action = a;
      QVERIFY2(action, qPrintable("no File menu action " + label));
      // The file dialog is modal: answer it from a timer while trigger() waits in its loop.
      bool answered = false;
      QTimer poll;
      poll.setInterval(50);
      connect(&poll, &QTimer::timeout, this, [&, p = path] {
        if (auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget())) {
          answered = true;
          poll.stop();
          // The name typed into the dialog's own field, as a user would.
          auto* name = dialog->findChild<QLineEdit*>("fileNameEdit");
          if (name) name->setText(p);
          static_cast<QDialog*>(dialog)->accept();  // QFileDialog::accept is protected
        }
      });
      poll.start();
      action->trigger();
      poll.stop();
      QVERIFY2(answered, qPrintable("no file dialog for " + label));
      QVERIFY2(QFile::exists(path), qPrintable(path));
    }
    Imf::InputFile in(exr.toStdString().c_str());
    QCOMPARE(in.header().dataWindow().max.x + 1, kW);
    QVERIFY(in.header().channels().findChannel("Y") != nullptr);
    QFile s(stl);
    QVERIFY(s.open(QIODevice::ReadOnly));
    const QByteArray bytes = s.readAll();
    QVERIFY(bytes.size() > 84);
    uint32_t n = 0;
    std::memcpy(&n, bytes.constData() + 80, 4);
    QCOMPARE(qint64(bytes.size()), qint64(84 + 50 * qint64(n)));
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    QVERIFY2(loader.LoadBinaryFromFile(&model, &err, &warn, glb.toStdString()), err.c_str());
    QCOMPARE(model.meshes.size(), size_t(1));
    QCOMPARE(model.images.size(), size_t(1));
  }

  void exportsTheSessionTimeLapse() {
    // File > Export time-lapse: the session's recording replayed into an H.264 MP4 that
    // libavformat opens, a frame every speed / fps simulated seconds and the painting last.
    grid_only_canvas(false);
    stroke(50.f, 0.6f);
    w_->settle();
    const QString path = dir_->path() + "/session.mp4";
    QVERIFY(w_->export_timelapse(path, TimelapseOptions{10, 1.0, false}));
    AVFormatContext* fmt = nullptr;
    QVERIFY(avformat_open_input(&fmt, path.toStdString().c_str(), nullptr, nullptr) == 0);
    QVERIFY(avformat_find_stream_info(fmt, nullptr) >= 0);
    QCOMPARE(int(fmt->nb_streams), 1);
    const AVStream* st = fmt->streams[0];
    const int64_t frames = st->nb_frames;
    const AVCodecID codec = st->codecpar->codec_id;
    avformat_close_input(&fmt);
    qInfo("time-lapse of the session: %s, %lld frames", avcodec_get_name(codec), static_cast<long long>(frames));
    QCOMPARE(codec, AV_CODEC_ID_H264);
    QVERIFY2(frames >= 3, "frame 0, frames of the stroke, the painting");
  }

#endif
  void recordingReplaysToSameCanvas() {
    // One thread on both sides: the CPU backend's parallel atomic sums make two runs of the same
    // stroke differ (the FLIP step amplifies the rounding), one thread makes a run reproducible.
    const int threads = on_sim(*w_, [](SimThread&) {
      const int n = omp_get_max_threads();
      omp_set_num_threads(1);
      return n;
    });
    grid_only_canvas(false);
    w_->paint_panel()->set_reload_each_stroke(false);  // a dirty brush: the dip and the wipe are the events
    PaintLoad red = w_->paint_panel()->current_paint();
    red.ryb[0] = 0.9f, red.ryb[1] = 0.1f, red.ryb[2] = 0.f;
    w_->dip(red);
    tablet_stroke(w_->view(), line_points(QPointF(25, 35), QPointF(125, 55), 24, 0.7f, 15.f, 0.f), 12);
    w_->settle();
    // A save between the strokes must not change what the simulation does next.
    QVERIFY(w_->save_to(dir_->path() + "/between.ora", true));
    w_->wipe(0.5f);
    tablet_stroke(w_->view(), line_points(QPointF(135, 85), QPointF(40, 75), 24, 0.5f, -10.f, 10.f), 12);
    w_->settle();
    QVERIFY(w_->sim()->recording_from_blank());
    const QString rec = dir_->path() + "/session.json";
    QVERIFY(w_->save_recording(rec));

    // `wetbrush replay` of the file on the same device. It ends by settling the particles into
    // the canvas; the studio's settled canvas (what it saves) is compared.
    const QString out = dir_->path() + "/replay.ora";
    const int64_t particles_live = w_->sim()->status().particles;
    QProcess cli;
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("OMP_NUM_THREADS", "1");
    cli.setProcessEnvironment(env);
    const QString stats = dir_->path() + "/replay-stats.json";
    // The recording names the studio's active window, so the replay needs no --window.
    cli.start(WB_CLI_PATH, {"replay", rec, "--device", "cpu", "--save", out, "--stats", stats, "--quiet"});
    QVERIFY(cli.waitForFinished(120000));
    QVERIFY2(cli.exitStatus() == QProcess::NormalExit && cli.exitCode() == 0, cli.readAllStandardError().constData());
    const std::vector<uint8_t> live_paint = volume_bytes(*w_, false);
    // Dryness per cell, in unorm16 codes, with the paint at rest.
    auto dryness_codes = [](TileStore& c) {
      std::vector<int> d;
      for (int id : c.allocated_tile_ids())
        for (uint16_t q : c.read_tile(id).dryness) d.push_back(q);
      return d;
    };
    const std::vector<int> live_dry = on_sim(*w_, [&](SimThread& s) {
      TileStore c = s.sim().settled_canvas_copy(Device{});
      return dryness_codes(c);
    });
    const std::vector<float> live = column_density(*w_);
    on_sim(*w_, [threads](SimThread&) {
      omp_set_num_threads(threads);
      return 0;
    });
    Painting replayed = load_painting(out.toStdString(), Device::parse("cpu"));
    QCOMPARE(replayed.canvas.dims().width, kW);
    const std::vector<float> again = column_density(replayed.canvas);
    QFile sf(stats);
    QVERIFY(sf.open(QIODevice::ReadOnly));
    const nlohmann::json st = nlohmann::json::parse(sf.readAll().toStdString());

    const Stroke s = load_stroke(rec.toStdString());
    double total = 0, diff = 0;
    for (size_t i = 0; i < live.size(); ++i) {
      total += live[i];
      diff += std::fabs(live[i] - again[i]);
    }
    qInfo("recorded session: %zu samples, %zu events, %lld steps; particles at the end: live %lld, replay %lld; "
          "paint (cell volumes) live %.3f, replayed %.3f, sum |live - replay| = %.3g",
          s.samples.size(), s.events.size(), (long long)st["steps"].get<int64_t>(), (long long)particles_live,
          (long long)st["particles"]["final"].get<int64_t>(), total, std::accumulate(again.begin(), again.end(), 0.0),
          diff);
    QCOMPARE(s.events.size(), size_t(2));  // the dip and the wipe
    QVERIFY(total > 5.0);
    // Same device, same thread count, same steps: the same canvas, bit for bit, although the
    // studio saved and closed undo records in between (with_settled_canvas leaves no trace).
    QCOMPARE(st["particles"]["final"].get<int64_t>(), particles_live);
    QVERIFY2(canonical_volume(replayed.canvas, false) == live_paint, "the replay reproduces the paint exactly");
    // Dryness is rounded to its 16-bit code wherever a tile catches up with the drying clock,
    // and the studio's canvas copies (brush changes) catch up at other moments than a replay.
    const std::vector<int> replay_dry = dryness_codes(replayed.canvas);
    QCOMPARE(replay_dry.size(), live_dry.size());
    int worst = 0;
    for (size_t i = 0; i < live_dry.size(); ++i) worst = std::max(worst, std::abs(live_dry[i] - replay_dry[i]));
    qInfo("dryness: largest difference live - replay %d codes of 65535", worst);
    QVERIFY2(worst <= 2, "the replay dries the painting as the studio did, to the code's rounding");
  }

  void closingWithUnsavedChangesAsks() {
    stroke(105.f, 0.5f);
    QVERIFY(w_->modified());
    bool asked = false;
    QTimer::singleShot(300, this, [&] {
      auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
      if (box) {
        asked = true;
        box->button(QMessageBox::Cancel)->click();
      }
    });
    const bool closed = w_->close();
    QVERIFY2(asked, "closing with unsaved changes asks");
    QVERIFY(!closed);
    QVERIFY(w_->isVisible());
    // Saved: closing does not ask.
    QVERIFY(w_->save_to(dir_->path() + "/closing.ora", true));
    bool asked_again = false;
    QTimer::singleShot(300, this, [&] {
      if (auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget())) {
        asked_again = true;
        box->button(QMessageBox::Cancel)->click();
      }
    });
    QVERIFY(w_->close());
    QVERIFY(!asked_again);
  }

  /// The real studio paints scripted strokes and autosaves every second; killed with SIGKILL
  /// while its pen is down, its next start offers the recovery file, and accepting it gives the
  /// painting of the last autosave, volume for volume.
  void killedMidStrokeRecoversLastAutosave() {
    const QString data = dir_->path() + "/killed";
    const QString recovery = data + "/recovery.ora";
    QProcess studio;
    QElapsedTimer clock;
    clock.start();
    // The test's own Xvfb display, WB_DEVICE and OMP_WAIT_POLICY are inherited.
    studio.start(WB_STUDIO_PATH, {"--device", "cpu", "--preset", "tiny", "--data-dir", data, "--autosave-interval",
                                  "1", "--paint-loop"});
    QVERIFY2(studio.waitForStarted(10000), qPrintable("wetbrush-studio did not start: " + studio.errorString()));
    QByteArray out;
    // Reads the studio's announcements until `done` holds, the studio exits or `ms` pass.
    const auto wait_for = [&](const std::function<bool()>& done, int ms) {
      QElapsedTimer t;
      t.start();
      while (!done() && studio.state() == QProcess::Running && t.elapsed() < ms) {
        studio.waitForReadyRead(20);
        out += studio.readAllStandardOutput();
      }
      return done();
    };
    const auto state = [&] {
      return QString("after %1 s: studio %2, stdout:\n%3\nstderr:\n%4")
          .arg(clock.elapsed() / 1000.0, 0, 'f', 1)
          .arg(studio.state() == QProcess::Running ? "running" : "exited")
          .arg(QString::fromUtf8(out), QString::fromUtf8(studio.readAllStandardError()));
    };
    QVERIFY2(wait_for([&] { return QFile::exists(recovery); }, 40000),
             qPrintable("no autosave appeared in the data folder " + state()));
    const double autosaved_s = clock.elapsed() / 1000.0;
    const qsizetype downs = out.count("pen down");
    QVERIFY2(wait_for([&] { return out.count("pen down") > downs; }, 30000),
             qPrintable("the studio did not start another stroke " + state()));
    // A quarter of the stroke's second of pen time: the simulation is mid-stroke.
    wait_for([] { return false; }, 250);
    QVERIFY2(studio.state() == QProcess::Running, qPrintable("the studio exited by itself " + state()));
    QVERIFY(::kill(pid_t(studio.processId()), SIGKILL) == 0);
    QVERIFY(studio.waitForFinished(10000));
    out += studio.readAllStandardOutput();
    const double killed_s = clock.elapsed() / 1000.0;
    QCOMPARE(studio.exitStatus(), QProcess::CrashExit);
    QVERIFY2(out.lastIndexOf("pen down") > out.lastIndexOf("pen up"),
             qPrintable("the kill came after the pen lifted " + state()));

    // The last autosave is what the recovery file holds now: a valid painting with the strokes.
    const QByteArray saved = read_bytes(recovery);
    QVERIFY2(!saved.isEmpty(), "the recovery file survived the kill");
    std::optional<Painting> last;
    try {
      last = load_painting_bytes(reinterpret_cast<const uint8_t*>(saved.constData()), size_t(saved.size()),
                                 recovery.toStdString(), Device::parse("cpu"));
    } catch (const std::exception& e) {
      QFAIL(qPrintable(QString("the recovery file is not a valid painting: ") + e.what()));
    }
    QCOMPARE(last->canvas.dims().width, kW);
    QCOMPARE(last->canvas.dims().height, kH);
    const std::vector<float> col = column_density(last->canvas);
    const double paint = std::accumulate(col.begin(), col.end(), 0.0);
    const QStringList temporaries = save_temporaries(data);
    qInfo("studio: first autosave after %.1f s, killed after %.1f s (stroke %lld, pen down); recovery file %lld "
          "bytes, %.1f cell volumes of paint; temporary files left by the kill: %lld",
          autosaved_s, killed_s, (long long)out.count("pen down"), (long long)saved.size(), paint,
          (long long)temporaries.size());
    QVERIFY2(paint > 5.0, "the autosave holds the painted strokes");

    // The next start: it offers the recovery, and Yes opens the autosaved painting, unsaved.
    QElapsedTimer recovering;
    recovering.start();
    StudioOptions o = options();
    o.data_dir = data;
    o.offer_recovery = true;
    BoxAnswerer answer([](QMessageBox&) { return QMessageBox::Yes; });
    auto next = std::make_unique<MainWindow>(o);
    next->show();
    QTRY_VERIFY2_WITH_TIMEOUT(!answer.boxes.empty(), "the next start offers to recover the painting", 10000);
    next->settle();
    QCOMPARE(answer.boxes.front().title, QString("Recover painting"));
    QVERIFY2(volume_bytes(*next) == canonical_volume(last->canvas),
             "the recovered painting is the last autosave, volume for volume");
    QVERIFY2(next->modified() && next->windowTitle().startsWith("Untitled *"),
             qPrintable("the recovered painting is open as unsaved: " + next->windowTitle()));
    QVERIFY(next->current_path().isEmpty());
    qInfo("recovery: offered and opened in %lld ms", (long long)recovering.elapsed());
  }

  void savingRemovesAnOlderRecoveryFile() {
    // After a save, a crash must not offer to go back to the autosave from before it: that
    // recovery file goes with the save; the next change is autosaved again.
    StudioOptions o = options();
    o.autosave_interval_s = 1;
    w_ = std::make_unique<MainWindow>(o);
    w_->show();
    QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    stroke(50.f, 0.6f);
    const QString recovery = w_->recovery_path();
    QTRY_VERIFY2_WITH_TIMEOUT(QFile::exists(recovery), "the changed painting is autosaved", 15000);
    QVERIFY(w_->save_to(dir_->path() + "/saved.ora", true));
    QVERIFY2(!QFile::exists(recovery), "the recovery file older than the save is gone");
    stroke(80.f, 0.6f);
    QTRY_VERIFY2_WITH_TIMEOUT(QFile::exists(recovery), "a change after the save is autosaved again", 15000);
  }

  void failedSaveToReadOnlyFolderKeepsPainting() {
    const QString folder = dir_->path() + "/read-only";
    const QString path = folder + "/painting.ora";
    QVERIFY(QDir().mkpath(folder));
    WritableAgain restore{folder};
    const auto read_only = [&] {
      return QFile::setPermissions(folder, QFile::ReadOwner | QFile::ExeOwner | QFile::ReadGroup | QFile::ExeGroup |
                                               QFile::ReadOther | QFile::ExeOther);
    };
    QVERIFY(read_only());
    if (::access(QFile::encodeName(folder).constData(), W_OK) == 0)
      QSKIP("a folder with mode 0555 is still writable here (running as root): no read-only folder to save into");
    QVERIFY(QFile::setPermissions(folder, QFile::ReadOwner | QFile::WriteOwner | QFile::ExeOwner));
    paint_and_save(path);
    if (QTest::currentTestFailed()) return;
    const QByteArray old_file = read_bytes(path);
    const std::vector<uint8_t> painting = volume_bytes(*w_);
    QVERIFY(read_only());
    expect_failed_saves(path, old_file, painting, "Permission denied");
    if (QTest::currentTestFailed()) return;
    QVERIFY(QFile::setPermissions(folder, QFile::ReadOwner | QFile::WriteOwner | QFile::ExeOwner));
    expect_save_after_repair(path, painting);
  }

  void failedSaveAtFileSizeLimitKeepsPainting() {
    if (!qEnvironmentVariableIsSet(kFileSizeChildEnv)) {
      // The limit and the ignored SIGXFSZ hold for the whole process: this test function runs
      // again in a child (this binary, this function alone), which sets them.
      QProcess child;
      QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
      env.insert(kFileSizeChildEnv, "1");
      child.setProcessEnvironment(env);
      child.setProcessChannelMode(QProcess::MergedChannels);
      child.start(QCoreApplication::applicationFilePath(), {"failedSaveAtFileSizeLimitKeepsPainting"});
      QVERIFY2(child.waitForFinished(120000), "the child test finished within two minutes");
      const QString out = QString::fromUtf8(child.readAll());
      qInfo("child test:\n%s", qPrintable(out));
      QVERIFY2(child.exitStatus() == QProcess::NormalExit && child.exitCode() == 0,
               qPrintable(QString("the child test failed (exit %1), its output is above").arg(child.exitCode())));
      QVERIFY2(out.contains("PASS   : StudioTest::failedSaveAtFileSizeLimitKeepsPainting()"), "the child ran the test");
      return;
    }
    const QString folder = dir_->path() + "/limited";
    const QString path = folder + "/painting.ora";
    QVERIFY(QDir().mkpath(folder));
    paint_and_save(path);
    if (QTest::currentTestFailed()) return;
    const QByteArray old_file = read_bytes(path);
    const std::vector<uint8_t> painting = volume_bytes(*w_);
    // Below the size of the painting's file: writing it fails with EFBIG, as on a full disk.
    constexpr rlim_t kLimit = 8 * 1024;
    qInfo("old file %lld bytes, file size limit %lld bytes", (long long)old_file.size(), (long long)kLimit);
    QVERIFY2(old_file.size() > qsizetype(2 * kLimit), "the painting's file is well over the limit");
    rlimit unlimited{};
    QVERIFY(::getrlimit(RLIMIT_FSIZE, &unlimited) == 0);
    ::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of killing the process
    rlimit limited = unlimited;
    limited.rlim_cur = kLimit;  // the soft limit only, so that it can be raised again
    QVERIFY(::setrlimit(RLIMIT_FSIZE, &limited) == 0);
    expect_failed_saves(path, old_file, painting, "File too large");
    QVERIFY(::setrlimit(RLIMIT_FSIZE, &unlimited) == 0);
    if (QTest::currentTestFailed()) return;
    expect_save_after_repair(path, painting);
  }

  void cleanupTestCase() {
    w_->undo_stack()->setClean();
    w_.reset();
  }
};

QTEST_MAIN(StudioTest)
#include "studio_test.moc"
