// Studio tests (Qt Test, run under xvfb-run for Mesa OpenGL): the window opens with an OpenGL
// canvas; synthesised tablet strokes paint under their path only; pressure widens the stroke;
// undo / redo restore the exact canvas; save then open gives the same volume; a recorded
// session replays to the same canvas; closing with unsaved changes asks.
#include <QApplication>
#include <QElapsedTimer>
#include <QMessageBox>
#include <QOpenGLContext>
#include <QPushButton>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>

#include <cmath>
#include <future>

#include "core/io/document.h"
#include "core/io/stroke.h"
#include "core/sim/replay.h"
#include "studio/demo.h"
#include "studio/main_window.h"
#include "studio/sim_paint.h"

using namespace wb;
using namespace wb::studio;

namespace {

/// Runs fn on the simulation thread and waits for its result.
template <class F>
auto on_sim(MainWindow& w, F fn) {
  using R = decltype(fn(*w.sim()));
  auto p = std::make_shared<std::promise<R>>();
  w.sim()->post([p, fn](SimThread& s) mutable { p->set_value(fn(s)); });
  return p->get_future().get();
}

/// Column paint (sum of density over z) per canvas cell, with the live window written back.
std::vector<float> column_density(MainWindow& w) {
  return on_sim(w, [](SimThread& s) {
    flush_simulation(s.sim());
    TileStore& c = s.sim().canvas();
    const CanvasDims d = c.dims();
    std::vector<float> col(size_t(d.width) * d.height, 0.f);
    for (int id : c.allocated_tile_ids()) {
      const TileData t = c.read_tile(id);
      for (int z = 0; z < d.depth; ++z)
        for (int ly = 0; ly < kTileSize; ++ly)
          for (int lx = 0; lx < kTileSize; ++lx) {
            const int x = t.tile_x * kTileSize + lx, y = t.tile_y * kTileSize + ly;
            if (x < d.width && y < d.height)
              col[size_t(y) * d.width + x] += t.density[(size_t(z) * kTileSize + ly) * kTileSize + lx];
          }
    }
    return col;
  });
}

std::vector<uint8_t> volume_bytes(MainWindow& w) {
  return on_sim(w, [](SimThread& s) {
    flush_simulation(s.sim());
    return encode_volume(s.sim().canvas());
  });
}

/// Painted width (cells with paint) across the column x.
int painted_width(const std::vector<float>& col, int width, int height, int x, int y0, int y1) {
  int n = 0;
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y) n += col[size_t(y) * width + x] > 0.05f;
  return n;
}

}  // namespace

class StudioTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> w_;
  static constexpr int kW = 320, kH = 240;

  StudioOptions options() {
    StudioOptions o;
    o.device = Device::parse("cpu");
    o.preset = QualityPreset::cpu();
    o.preset.canvas_width = kW;
    o.preset.canvas_height = kH;
    o.preset.canvas_depth = 32;
    o.preset.ao_rays = 4;
    BrushSpec b = default_brush(BrushShape::Round);
    b.bristles = 48;
    b.length = 40.f;
    b.width = b.thickness = 16.f;
    b.samples_per_bristle = 56;
    o.brush = b;
    o.data_dir = dir_.path() + "/data";
    o.offer_recovery = false;
    return o;
  }

  void stroke(float y, float pressure, float x0 = 60.f, float x1 = 260.f) {
    QElapsedTimer t;
    t.start();
    tablet_stroke(w_->view(), line_points(QPointF(x0, y), QPointF(x1, y), 40, pressure), 10);
    w_->settle();
    const SimStatus st = w_->sim()->status();
    qInfo("stroke: %lld ms wall, %lld steps so far, %.1f ms/step, %lld particles", (long long)t.elapsed(),
          (long long)st.steps, st.step_ms, (long long)st.particles);
  }

 private Q_SLOTS:
  void initTestCase() {
    QVERIFY(dir_.isValid());
    w_ = std::make_unique<MainWindow>(options());
    w_->show();
    QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    w_->settle();
  }

  void windowOpensWithOpenGL() {
    QVERIFY(w_->view()->context() != nullptr);
    QVERIFY(w_->view()->context()->isValid());
    const QImage img = w_->view()->grabFramebuffer();
    QVERIFY(!img.isNull());
    QCOMPARE(w_->view()->canvas_size(), QSize(kW, kH));
  }

  void tabletEventsCarryPressureTiltRotation() {
    PenInput got;
    bool seen = false;
    auto c = connect(w_->view(), &CanvasView::penPress, this, [&](PenInput p, double) {
      got = p;
      seen = true;
    });
    std::vector<ScriptPoint> pts{{QPointF(100, 100), 0.64f, 20.f, -10.f, 30.f}};
    tablet_stroke(w_->view(), pts, 5);
    disconnect(c);
    QVERIFY(seen);
    QCOMPARE(got.pressure, 0.64f);  // pressure curve exponent 1
    QVERIFY(std::fabs(got.tilt_x - 20.f) < 1e-3f && std::fabs(got.tilt_y + 10.f) < 1e-3f);
    QVERIFY(std::fabs(got.twist - 30.f) < 1e-3f);
    QVERIFY(std::fabs(got.x - 100.f) < 1.f && std::fabs(got.y - 100.f) < 1.f);
    w_->settle();
    w_->undo_stack()->clear();
  }

  void paintUnderPathOnly() {
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
    stroke(120.f, 0.8f);
    const std::vector<float> col = column_density(*w_);
    double near = 0, far = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const float v = col[size_t(y) * kW + x];
        // The path with the brush's footprint and bristle splay around it (length 40).
        const bool by_path = x >= 60 - 45 && x <= 260 + 45 && std::abs(y - 120) <= 45;
        // A column holding less than a twentieth of a cell of paint is a film, not a mark.
        if (v > 0.05f) (by_path ? near : far) += v;
      }
    int bx0 = kW, by0 = kH, bx1 = -1, by1 = -1;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        if (col[size_t(y) * kW + x] > 0.f) bx0 = std::min(bx0, x), by0 = std::min(by0, y), bx1 = std::max(bx1, x), by1 = std::max(by1, y);
    qInfo("paint near the path %.1f, elsewhere %.3f (cell volumes); painted box x %d..%d, y %d..%d", near, far, bx0, bx1, by0, by1);
    QVERIFY2(near > 50.0, "the stroke left paint under its path");
    QVERIFY2(far <= 1e-6 * near, "no paint away from the path");
    // Paint along the path, not only at one end.
    for (int x : {90, 160, 230}) QVERIFY2(painted_width(col, kW, kH, x, 100, 140) > 0, "paint along the whole path");
  }

  void pressureChangesWidth() {
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
    stroke(60.f, 0.15f);
    stroke(170.f, 0.95f);
    const std::vector<float> col = column_density(*w_);
    int light = 0, heavy = 0;
    for (int x = 130; x <= 190; x += 10) {
      light += painted_width(col, kW, kH, x, 20, 110);
      heavy += painted_width(col, kW, kH, x, 120, 230);
    }
    qInfo("painted width summed over 7 columns: light %d, heavy %d cells", light, heavy);
    QVERIFY2(heavy > light, "a harder press paints a wider stroke");
  }

  void undoRestoresExactCanvasRedoReapplies() {
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
    stroke(80.f, 0.6f);
    const std::vector<uint8_t> before = volume_bytes(*w_);
    const int n0 = w_->undo_stack()->count();
    stroke(150.f, 0.7f, 40.f, 280.f);
    QCOMPARE(w_->undo_stack()->count(), n0 + 1);
    const std::vector<uint8_t> after = volume_bytes(*w_);
    QVERIFY(after != before);
    w_->undo_stack()->undo();
    w_->settle();
    QVERIFY2(volume_bytes(*w_) == before, "undo restores the canvas exactly");
    w_->undo_stack()->redo();
    w_->settle();
    QVERIFY2(volume_bytes(*w_) == after, "redo re-applies the stroke exactly");
  }

  void saveThenOpenGivesSameVolume() {
    const std::vector<uint8_t> now = volume_bytes(*w_);
    const QString path = dir_.path() + "/painting.ora";
    QVERIFY(w_->save_to(path, true));
    QVERIFY(!w_->modified());
    QVERIFY(w_->open_from(path));
    w_->settle();
    QVERIFY2(volume_bytes(*w_) == now, "save then open gives the same paint volume");
  }

  void recordingReplaysToSameCanvas() {
    w_->new_canvas(kW, kH, QColor(240, 235, 225));
    w_->settle();
    PaintLoad red = w_->paint_panel()->current_paint();
    red.ryb[0] = 0.9f, red.ryb[1] = 0.1f, red.ryb[2] = 0.f;
    w_->dip(red);
    tablet_stroke(w_->view(), line_points(QPointF(50, 70), QPointF(250, 110), 30, 0.7f, 15.f, 0.f), 10);
    w_->settle();
    w_->wipe(0.5f);
    tablet_stroke(w_->view(), line_points(QPointF(270, 170), QPointF(80, 150), 30, 0.5f, -10.f, 10.f), 10);
    w_->settle();
    QVERIFY(w_->sim()->recording_from_blank());
    const QString rec = dir_.path() + "/session.json";
    QVERIFY(w_->save_recording(rec));
    const std::vector<float> live = column_density(*w_);

    // Replay the file through the replay driver `wetbrush replay` uses, on the same device.
    Stroke s = load_stroke(rec.toStdString());
    StrokePlayer player(s);
    SimConfig cfg;
    cfg.device = Device::parse("cpu");
    cfg.canvas = s.canvas;
    cfg.brush = s.brush;
    Simulator sim(cfg, player.pose_at(player.t_begin()));
    Replay replay(sim, player);
    while (replay.advance()) {
    }
    flush_simulation(sim);
    std::vector<float> again(live.size(), 0.f);
    for (int id : sim.canvas().allocated_tile_ids()) {
      const TileData t = sim.canvas().read_tile(id);
      for (int z = 0; z < s.canvas.depth; ++z)
        for (int ly = 0; ly < kTileSize; ++ly)
          for (int lx = 0; lx < kTileSize; ++lx) {
            const int x = t.tile_x * kTileSize + lx, y = t.tile_y * kTileSize + ly;
            if (x < kW && y < kH) again[size_t(y) * kW + x] += t.density[(size_t(z) * kTileSize + ly) * kTileSize + lx];
          }
    }
    double total = 0, diff = 0;
    for (size_t i = 0; i < live.size(); ++i) {
      total += live[i];
      diff += std::fabs(live[i] - again[i]);
    }
    qInfo("recorded session: %zu samples, %zu events; live paint %.2f, |live - replay| = %.3g", s.samples.size(),
          s.events.size(), total, diff);
    QVERIFY(total > 10.0);
    // Same device, same steps: equal up to the order of floating-point accumulation (atomics).
    QVERIFY2(diff <= 1e-3 * total, "the replay reproduces the painting");
  }

  void closingWithUnsavedChangesAsks() {
    stroke(200.f, 0.5f);
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
    w_->undo_stack()->setClean();
  }

  void cleanupTestCase() {
    w_->undo_stack()->setClean();
    w_.reset();
  }
};

QTEST_MAIN(StudioTest)
#include "studio_test.moc"
