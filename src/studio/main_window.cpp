#include "studio/main_window.h"

#include <QApplication>
#include <QCloseEvent>
#include <QColorDialog>
#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDir>
#include <QDockWidget>
#include <QFile>
#include <QFileDialog>
#include <QProgressDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QInputDialog>
#include <QLineEdit>
#include <QMenuBar>
#include <QMessageBox>
#include <QPushButton>
#include <QSettings>
#include <QSpinBox>
#include <QDoubleSpinBox>
#include <QStandardPaths>
#include <QStatusBar>
#include <QThread>
#include <QThreadPool>
#include <QUndoCommand>

#include <chrono>
#include <cstdio>
#include <cmath>
#include <future>
#include <atomic>

#include "core/io/brush_json.h"
#include "core/io/document.h"
#include "core/exec/error.h"
#include "core/exec/memory.h"
#include "core/io/material_maps.h"
#if WB_WITH_MEDIA
#include "media/relief_export.h"
#endif
#include "core/io/png.h"

namespace wb::studio {
namespace {

/// One whole stroke, whose record the painting's Session keeps: undo writes back the tiles as
/// they were, redo as they became (Session::undo, Session::redo). The Session's history and this
/// stack grow and shrink together, a stroke at a time, to the same limit.
class StrokeCommand : public QUndoCommand {
 public:
  StrokeCommand(SimThread* sim, std::function<void()> on_change)
      : QUndoCommand("Stroke"), sim_(sim), on_change_(std::move(on_change)) {}
  void undo() override { apply(false); }
  void redo() override {
    if (first_) {  // the stroke is already on the canvas
      first_ = false;
      return;
    }
    apply(true);
  }

 private:
  void apply(bool after) {
    sim_->post([after](SimThread& s) { s.undo_stroke(after); });
    on_change_();
  }
  SimThread* sim_;
  std::function<void()> on_change_;
  bool first_ = true;
};

}  // namespace

MainWindow::MainWindow(const StudioOptions& options, QWidget* parent)
    : QMainWindow(parent),
      options_(options),
      clock_(options.preset.canvas_width, options.preset.canvas_height) {
  if (options_.data_dir.isEmpty())
    options_.data_dir = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation);
  QDir().mkpath(options_.data_dir);
  // The memory budget: --memory-limit or WB_MEMORY_LIMIT (main.cpp), else the saved setting.
  if (wb::mem::budget(false) == 0) {
    const QString saved = QSettings(options_.data_dir + "/studio.ini", QSettings::IniFormat).value("memory_limit").toString();
    try {
      wb::mem::set_budget_from(saved.toStdString());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "wetbrush-studio: the saved memory limit is ignored: %s\n", wb::user_message(e).c_str());
    }
  }

  const QualityPreset& q = options_.preset;
  SimConfig cfg;
  cfg.device = options_.device;
  cfg.canvas = CanvasDims{q.canvas_width, q.canvas_height, q.canvas_depth};
  cfg.brush = q.start_brush();
  if (options_.brush) cfg.brush = *options_.brush;
  cfg.window = q.window();
  cfg.params.transfer.candidate_split = q.candidate_split;
  RenderParams rp;
  rp.ao_rays = q.ao_rays;
  sim_ = std::make_unique<SimThread>(cfg, rp, kUndoLimit);

  view_ = new CanvasView(options_.view);
  view_->set_frame_source([s = sim_.get()](QImage& img) { return s->take_frame(img); });
  view_->set_canvas_size(cfg.canvas.width, cfg.canvas.height);
  view_->set_cursor_radius(cfg.brush.width * 0.5f);
  setCentralWidget(view_);
  connect(sim_.get(), &SimThread::frameReady, view_, &CanvasView::frame_ready);
  connect(sim_.get(), &SimThread::failed, this, [this](const QString& m) { statusBar()->showMessage("Error: " + m, 30000); });

  undo_ = new QUndoStack(this);
  undo_->setUndoLimit(kUndoLimit);
  connect(undo_, &QUndoStack::cleanChanged, this, [this] { update_title(); });
  connect(sim_.get(), &SimThread::strokeFinished, this, [this] {
    undo_->push(new StrokeCommand(sim_.get(), [this] { clock_.restart(); }));
    autosave_due_ = true;
    idle_save_timer_.start();
  });

  // The palette: its own small canvas and simulation, the same brush.
  palette_ = new PalettePanel(cfg, rp, q.palette_width, q.palette_height, view_->kind());
  connect(palette_, &PalettePanel::aboutToPaint, this, [this] { carry_brush(true); });
  connect(palette_, &PalettePanel::placePaint, this,
          [this](QPointF c) { palette_->put_paint(c, paint_panel_->current_paint()); });
  connect(palette_, &PalettePanel::pickColor, this, [this](QPointF c) { pick_color(c, palette_->sim()); });
  connect(palette_->sim(), &SimThread::failed, this,
          [this](const QString& m) { statusBar()->showMessage("Palette error: " + m, 10000); });

  // Pen input -> session clock -> simulation thread.
  connect(view_, &CanvasView::penPress, this, [this](PenInput p, double t) {
    carry_brush(false);
    if (paint_panel_->reload_each_stroke()) {
      // A clean brush loaded from the selected well; events in the recording, so a replay does the same.
      StrokeEvent clean;
      clean.kind = StrokeEventKind::Clean;
      push_clock(clock_.event(clean));
      push_clock(clock_.event(dip_event(paint_panel_->current_paint())));
    }
    push_clock(clock_.press(p, t, wall_now()));
  });
  connect(view_, &CanvasView::penMove, this, [this](PenInput p, double t) { push_clock(clock_.move(p, t, wall_now())); });
  connect(view_, &CanvasView::pickColor, this, [this](QPointF c) { pick_color(c); });
  connect(view_, &CanvasView::penRelease, this, [this](PenInput p, double t) {
    push_clock(clock_.release(p, t));
    for (const StrokeEvent& e : pending_events_) push_clock(clock_.event(e));
    pending_events_.clear();
  });
  hold_timer_.setInterval(8);
  // A held pen's repeats, and the running paint's steps while the pen is away (an easel).
  connect(&hold_timer_, &QTimer::timeout, this, [this] { push_clock(clock_.tick(wall_now(), sim_->paint_runs_on())); });
  hold_timer_.start();

  // Panels.
  brush_panel_ = new BrushPanel;
  brush_panel_->set_brush(cfg.brush);
  brush_panel_->set_preset_dir(options_.data_dir + "/brushes");
  connect(brush_panel_, &BrushPanel::brushChanged, this, [this](BrushSpec b) {
    b.samples_per_bristle = std::max(options_.preset.samples_per_bristle, samples_needed(b));
    try {
      validate_brush(b, "brush");
    } catch (const std::exception& e) {
      statusBar()->showMessage(QString::fromStdString(user_message(e)), 5000);
      return;
    }
    view_->set_cursor_radius(b.width * 0.5f);
    palette_->view()->set_cursor_radius(b.width * 0.5f);
    for (SimThread* sim : {sim_.get(), palette_->sim()})
      sim->post([b](SimThread& s) {
        SimConfig c = s.config();
        c.brush = b;
        s.rebuild(c, true);
      });
    clock_.restart();
    palette_->restart_clock();
  });
  paint_panel_ = new PaintPanel;
  paint_panel_->set_reload_each_stroke(
      QSettings(options_.data_dir + "/studio.ini", QSettings::IniFormat).value("reload_each_stroke", true).toBool());
  connect(paint_panel_, &PaintPanel::reloadToggled, this, [this](bool on) {
    QSettings(options_.data_dir + "/studio.ini", QSettings::IniFormat).setValue("reload_each_stroke", on);
  });
  connect(paint_panel_, &PaintPanel::dip, this, [this](PaintLoad p) { dip(p); });
  connect(paint_panel_, &PaintPanel::wipe, this, [this](float f) { wipe(f); });
  connect(paint_panel_, &PaintPanel::clean, this, [this] { clean_brush(); });
  view_panel_ = new ViewPanel;
  connect(view_panel_, &ViewPanel::lightingChanged, this, [this](float az, float el, float relief) {
    const float a = az * 3.14159265f / 180.f, e = el * 3.14159265f / 180.f;
    const Vec3 dir(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e));
    sim_->post([dir, relief](SimThread& s) {
      s.renderer().params().light_dir = dir;
      s.renderer().params().diffuse = relief;
      s.renderer().params().ambient = 1.1f - relief;
      s.invalidate_all();
    });
  });
  // The light follows a right-button drag on the canvas: half a degree of direction per pixel
  // across, a quarter degree of height per pixel up; the view re-renders once, on release.
  connect(view_, &CanvasView::lightDrag, this, [this](QPointF moved, bool done) {
    if (!light_dragging_) {
      light_dragging_ = true;
      drag_azimuth_ = view_panel_->azimuth();
      drag_elevation_ = view_panel_->elevation();
    }
    view_panel_->set_light(drag_azimuth_ - 0.5f * float(moved.x()), drag_elevation_ - 0.25f * float(moved.y()), done);
    if (done) light_dragging_ = false;
  });
  connect(view_panel_, &ViewPanel::obliqueToggled, this, [this](bool on) {
    oblique_dock_->setVisible(on);
    if (on) refresh_oblique();
  });
  connect(sim_.get(), &SimThread::obliqueReady, this, [this](QImage img) {
    oblique_image_ = img;
    ++oblique_renders_;
    oblique_label_->setPixmap(QPixmap::fromImage(img));
  });
  connect(sim_.get(), &SimThread::frameReady, this, [this] {
    if (view_panel_->oblique() && !oblique_timer_.isActive()) oblique_timer_.start();
  });
  oblique_timer_.setSingleShot(true);
  oblique_timer_.setInterval(300);
  connect(&oblique_timer_, &QTimer::timeout, this, [this] { refresh_oblique(); });
  connect(view_panel_, &ViewPanel::pressureChanged, this, [this](float mp, float gamma) {
    view_->set_mouse_pressure(mp);
    view_->set_pressure_gamma(gamma);
  });
  const auto dock = [this](QWidget* w, const QString& title) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(title);
    d->setWidget(w);
    d->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
    addDockWidget(Qt::RightDockWidgetArea, d);
  };
  dock(brush_panel_, "Brush");
  dock(paint_panel_, "Paint");
  dock(palette_, "Palette (Ctrl + click: put out paint)");
  brush_preview_ = new BrushPreview;
  dock(brush_preview_, "Brush preview");
  dock(view_panel_, "View and input");
  // The preview follows the brush with every frame while painting, and the status timer otherwise.
  for (SimThread* sim : {sim_.get(), palette_->sim()})
    connect(sim, &SimThread::frameReady, brush_preview_, [this, sim] {
      if (sim == (brush_on_palette_ ? palette_->sim() : sim_.get())) brush_preview_->set_picture(sim->brush_picture());
    });
  oblique_label_ = new QLabel;
  oblique_label_->setAlignment(Qt::AlignCenter);
  oblique_label_->setMinimumSize(240, 120);
  oblique_dock_ = new QDockWidget("Oblique view", this);
  oblique_dock_->setObjectName("Oblique view");
  oblique_dock_->setWidget(oblique_label_);
  addDockWidget(Qt::BottomDockWidgetArea, oblique_dock_);
  oblique_dock_->hide();
  connect(oblique_dock_, &QDockWidget::visibilityChanged, this, [this](bool visible) {
    if (!visible && !oblique_dock_->isVisible()) view_panel_->set_oblique(false);
  });

  // Status bar.
  status_sim_ = new QLabel;
  status_device_ = new QLabel;
  status_view_ = new QLabel;
  status_behind_ = new QLabel;
  status_behind_->setStyleSheet("color: #c0392b");
  status_behind_->hide();
  statusBar()->addPermanentWidget(status_behind_);
  statusBar()->addPermanentWidget(status_sim_);
  statusBar()->addPermanentWidget(status_view_);
  statusBar()->addPermanentWidget(status_device_);
  status_timer_.setInterval(500);
  connect(&status_timer_, &QTimer::timeout, this, [this] { update_status(); });
  status_timer_.start();

  build_menus();

  // Autosave: every few minutes when changed, and a moment after each stroke when idle.
  autosave_timer_.setInterval(options_.autosave_interval_s * 1000);
  connect(&autosave_timer_, &QTimer::timeout, this, [this] { autosave(); });
  autosave_timer_.start();
  idle_save_timer_.setSingleShot(true);
  idle_save_timer_.setInterval(3000);
  connect(&idle_save_timer_, &QTimer::timeout, this, [this] {
    if (sim_->status().idle && !clock_.down())
      autosave();
    else
      idle_save_timer_.start();
  });

  for (SimThread* sim : {sim_.get(), palette_->sim()})
    sim->post([p = paint_panel_->current_paint()](SimThread& s) {
      s.set_paint(p);
      s.restart_recording(true);
    });
  resize(1400, 900);
  update_title();
  if (!options_.open_path.isEmpty())
    open_from(options_.open_path);
  else if (options_.offer_recovery)
    QTimer::singleShot(0, this, [this] { check_recovery(); });
}

MainWindow::~MainWindow() {
  QThreadPool::globalInstance()->waitForDone();
  sim_.reset();
}

QString MainWindow::recovery_path() const { return options_.data_dir + "/recovery.ora"; }

void MainWindow::build_menus() {
  QMenu* file = menuBar()->addMenu("&File");
  file->addAction("&New canvas...", QKeySequence::New, this, [this] {
    QDialog d(this);
    d.setWindowTitle("New canvas");
    auto* form = new QFormLayout(&d);
    auto* unit = new QComboBox;
    unit->addItems({"cells (0.2 mm)", "cm"});
    auto* w = new QSpinBox;
    auto* h = new QSpinBox;
    for (auto* s : {w, h}) s->setRange(16, 16384);
    w->setValue(view_->canvas_size().width());
    h->setValue(view_->canvas_size().height());
    QColor paper(237, 232, 219);
    auto* paper_b = new QPushButton("Paper colour...");
    connect(paper_b, &QPushButton::clicked, &d, [&] {
      const QColor c = QColorDialog::getColor(paper, &d, "Paper colour");
      if (c.isValid()) paper = c;
    });
    // The ground: a woven canvas is laid as dried primer in the paper's colour (docs/STUDIO.md
    // "Canvas texture"); its sizes start at the weave's defaults.
    auto* weave = new QComboBox;
    weave->addItem("Smooth board", int(Weave::Smooth));
    weave->addItem("Linen", int(Weave::Linen));
    weave->addItem("Cotton duck", int(Weave::CottonDuck));
    auto* thread = new QDoubleSpinBox;
    thread->setRange(kThreadMmMin, kThreadMmMax);
    thread->setSingleStep(0.1);
    thread->setSuffix(" mm");
    thread->setToolTip("Distance between neighbouring threads (the grid's cell is 0.2 mm)");
    auto* relief = new QDoubleSpinBox;
    relief->setRange(kReliefMmMin, kReliefMmMax);
    relief->setSingleStep(0.05);
    relief->setSuffix(" mm");
    relief->setToolTip("Height of a thread's crown over the hollows of the weave");
    auto weave_changed = [=] {
      const CanvasGround g = CanvasGround::of(Weave(weave->currentData().toInt()));
      thread->setValue(g.thread_mm);
      relief->setValue(g.relief_mm);
      thread->setEnabled(g.weave != Weave::Smooth);
      relief->setEnabled(g.weave != Weave::Smooth);
    };
    connect(weave, &QComboBox::currentIndexChanged, &d, weave_changed);
    weave_changed();
    form->addRow("Unit", unit);
    form->addRow("Width", w);
    form->addRow("Height", h);
    form->addRow(paper_b);
    form->addRow("Canvas", weave);
    form->addRow("Thread spacing", thread);
    form->addRow("Relief", relief);
    auto* bb = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    form->addRow(bb);
    connect(bb, &QDialogButtonBox::accepted, &d, &QDialog::accept);
    connect(bb, &QDialogButtonBox::rejected, &d, &QDialog::reject);
    if (d.exec() != QDialog::Accepted || !maybe_save()) return;
    const int k = unit->currentIndex() == 1 ? 50 : 1;  // 1 cm = 50 cells
    CanvasGround g = CanvasGround::of(Weave(weave->currentData().toInt()));
    g.thread_mm = float(thread->value());
    g.relief_mm = float(relief->value());
    const QString why = ground_refusal(w->value() * k, h->value() * k, g);
    if (!why.isEmpty()) {
      QMessageBox::warning(this, "New canvas", why);
      return;
    }
    new_canvas(w->value() * k, h->value() * k, paper, g);
  });
  file->addAction("&Open...", QKeySequence::Open, this, [this] {
    if (!maybe_save()) return;
    const QString p = QFileDialog::getOpenFileName(this, "Open painting", QString(), "OpenRaster (*.ora)");
    if (!p.isEmpty()) open_from(p);
  });
  recent_menu_ = file->addMenu("Open &recent");
  rebuild_recent_menu();
  file->addAction("&Save", QKeySequence::Save, this, [this] {
    if (path_.isEmpty()) {
      const QString p = QFileDialog::getSaveFileName(this, "Save painting", "painting.ora", "OpenRaster (*.ora)");
      if (!p.isEmpty()) save_to(p);
    } else {
      save_to(path_);
    }
  });
  file->addAction("Save &as...", QKeySequence::SaveAs, this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Save painting", "painting.ora", "OpenRaster (*.ora)");
    if (!p.isEmpty()) save_to(p);
  });
  file->addSeparator();
  file->addAction("Export &PNG...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Export PNG", "painting.png", "PNG (*.png)");
    if (!p.isEmpty()) export_png(p);
  });
  file->addAction("Export &height and normal maps...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Export maps (base name)", "painting", "PNG (*.png)");
    if (p.isEmpty()) return;
    QString base = p;
    if (base.endsWith(".png")) base.chop(4);
    export_maps(base + "-height.png", base + "-normal.png");
  });
#if WB_WITH_MEDIA
  file->addAction("Export height (&OpenEXR)...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Export height in mm", "painting.exr", "OpenEXR (*.exr)");
    if (!p.isEmpty()) export_relief(p, "", "");
  });
  file->addAction("Export relief for printing (&STL)...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Export STL solid", "painting.stl", "STL (*.stl)");
    if (!p.isEmpty()) export_relief("", p, "");
  });
  file->addAction("Export relief for 3D (&glTF)...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Export glTF binary", "painting.glb", "glTF binary (*.glb)");
    if (!p.isEmpty()) export_relief("", "", p);
  });
  file->addAction("Export &time-lapse...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Export time-lapse", "painting.mp4", "MP4 video (*.mp4)");
    if (!p.isEmpty()) export_timelapse(p);
  });
#endif
  file->addAction("Save &recording...", this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, "Save recording", "session.json", "Stroke file (*.json)");
    if (!p.isEmpty()) save_recording(p);
  });
  file->addSeparator();
  file->addAction("&Quit", QKeySequence::Quit, this, &QWidget::close);

  QMenu* edit = menuBar()->addMenu("&Edit");
  QAction* u = undo_->createUndoAction(this, "&Undo");
  u->setShortcut(QKeySequence::Undo);
  QAction* r = undo_->createRedoAction(this, "&Redo");
  r->setShortcut(QKeySequence::Redo);
  edit->addAction(u);
  edit->addAction(r);
  edit->addSeparator();
  edit->addAction("&Memory limit\u2026", this, &MainWindow::ask_memory_limit);

  QMenu* canvas = menuBar()->addMenu("&Canvas");
  canvas->addAction("&Dry canvas", QKeySequence(Qt::CTRL | Qt::Key_D), this, [this] { dry_canvas(); });
  canvas->addAction("Easel &tilt\u2026", this, [this] {
    bool ok = false;
    const double deg = QInputDialog::getDouble(this, "Easel tilt",
                                               "Tilt of the canvas from the table, degrees (0 flat, 90 upright on an "
                                               "easel):\nwet paint runs down the canvas as gravity and its stiffness decide.",
                                               double(tilt_), 0.0, 90.0, 0, &ok);
    if (ok) set_tilt(float(deg));
  });
  canvas->addAction("D&ip brush", QKeySequence(Qt::Key_D), this, [this] { dip(paint_panel_->current_paint()); });
  canvas->addAction("&Wipe brush", QKeySequence(Qt::Key_W), this, [this] { wipe(0.5f); });
  canvas->addAction("&Clean brush", QKeySequence(Qt::Key_C), this, [this] { clean_brush(); });
  canvas->addAction("Clean &palette", this, [this] {
    palette_->sim()->post([](SimThread& s) {
      s.session().clear();
      s.invalidate_all();
    });
  });

  QMenu* view = menuBar()->addMenu("&View");
  view->addAction("&Fit (0)", this, [this] { view_->fit(); });
  view->addAction("&1:1 (1)", this, [this] { view_->set_view(view_->center(), 1.f, view_->rotation_deg()); });
  view->addAction("Zoom &in (+)", this, [this] { view_->zoom_by(1.25f, QPointF(view_->width() / 2.0, view_->height() / 2.0)); });
  view->addAction("Zoom &out (-)", this, [this] { view_->zoom_by(0.8f, QPointF(view_->width() / 2.0, view_->height() / 2.0)); });
  view->addAction("&Rotate 15\u00b0 (R)", this, [this] { view_->set_view(view_->center(), view_->zoom(), view_->rotation_deg() + 15.f); });
  view->addAction("Reset rotation", this, [this] { view_->set_view(view_->center(), view_->zoom(), 0.f); });
}

void MainWindow::push_clock(const ClockOutput& out) {
  sim_->push(out);
}

void MainWindow::carry_brush(bool to_palette) {
  if (to_palette == brush_on_palette_) return;
  SimThread* from = to_palette ? sim_.get() : palette_->sim();
  SimThread* to = to_palette ? palette_->sim() : sim_.get();
  // The receiving thread waits for the paint; the giving one never waits for it, so two carries
  // in a row (there and back) cannot wait on each other.
  auto paint = std::make_shared<std::promise<BristleLoadHost>>();
  std::shared_future<BristleLoadHost> arrives = paint->get_future().share();
  from->post([paint](SimThread& s) {
    try {
      paint->set_value(s.give_brush_paint());
    } catch (...) {
      paint->set_exception(std::current_exception());
    }
  });
  to->post([arrives](SimThread& s) { s.receive_brush_paint(arrives.get()); });
  if (to_palette)
    palette_->restart_clock();
  else
    clock_.restart();
  brush_on_palette_ = to_palette;
}

void MainWindow::send_event(StrokeEvent e) {
  // The brush's events go where the brush is; drying is the painting's.
  if (brush_on_palette_ && e.kind != StrokeEventKind::Dry) {
    palette_->send_event(e);
    return;
  }
  if (clock_.down()) {
    pending_events_.push_back(e);
    return;
  }
  push_clock(clock_.event(e));
}

StrokeEvent MainWindow::dip_event(const PaintLoad& p) {
  StrokeEvent e;
  e.kind = StrokeEventKind::Dip;
  for (int c = 0; c < 3; ++c) e.ryb[c] = p.ryb[c];
  e.oil = p.oil;
  e.load = p.load;
  return e;
}

void MainWindow::dip(const PaintLoad& p) { send_event(dip_event(p)); }

void MainWindow::wipe(float fraction) {
  StrokeEvent e;
  e.kind = StrokeEventKind::Wipe;
  e.fraction = fraction;
  send_event(e);
}

void MainWindow::clean_brush() {
  StrokeEvent e;
  e.kind = StrokeEventKind::Clean;
  send_event(e);
}

void MainWindow::dry_canvas() {
  StrokeEvent e;
  e.kind = StrokeEventKind::Dry;
  send_event(e);
  // Undo records are tiles before and after a stroke: restoring wet tiles over a dried
  // layer would undo the drying too, so drying starts a new history.
  undo_->clear();
  dirty_ = true;
  update_title();
}

void MainWindow::refresh_oblique() {
  if (!view_panel_->oblique()) return;
  // Not while painting: the render would hold up the simulation. Asked again when it is idle.
  if (!sim_->status().idle) {
    oblique_timer_.start();
    return;
  }
  sim_->post([](SimThread& s) { s.render_oblique(30.f, 720); });
}

std::optional<std::array<float, 3>> MainWindow::pick_color(QPointF canvas, SimThread* from) {
  if (!from) from = sim_.get();
  // The pigment the renderer blends for the top view there, read between two steps (one image
  // tile rendered): what the artist sees, a glaze with the paper it lets through.
  const int x = int(std::floor(canvas.x())), y = int(std::floor(canvas.y()));
  auto done = std::make_shared<std::promise<std::optional<Vec3>>>();
  std::future<std::optional<Vec3>> result = done->get_future();
  from->post([done, x, y](SimThread& s) {
    try {
      done->set_value(s.session().pick(x, y));
    } catch (...) {
      done->set_exception(std::current_exception());
    }
  });
  std::optional<Vec3> ryb;
  try {
    ryb = result.get();
  } catch (const std::exception& e) {
    statusBar()->showMessage(QString("Eyedropper: %1").arg(QString::fromStdString(user_message(e))), 5000);
    return std::nullopt;
  }
  if (!ryb) {
    statusBar()->showMessage("Eyedropper: no paint there", 3000);
    return std::nullopt;
  }
  const std::array<float, 3> c{ryb->x, ryb->y, ryb->z};
  paint_panel_->set_well_ryb(paint_panel_->current_well(), c);
  statusBar()->showMessage(QString("Eyedropper: well %1 takes the paint at (%2, %3)")
                               .arg(paint_panel_->current_well() + 1)
                               .arg(x)
                               .arg(y),
                           3000);
  return c;
}

QString MainWindow::ground_refusal(int width, int height, const CanvasGround& g) const {
  const std::string why = wb::ground_refusal(g, width, height, options_.preset.canvas_depth, GridParams{}.cell_size);
  return why.empty() ? QString() : QString::fromStdString(why) + ". Choose less relief, a smaller canvas or a smooth board.";
}

void MainWindow::set_tilt(float degrees) {
  tilt_ = degrees;
  // The palette stays on the table; the canvas's simulator is made anew with the painting on it.
  sim_->post([degrees](SimThread& s) {
    SimConfig c = s.config();
    c.params.grid.tilt = degrees;
    s.rebuild(c, true);
  });
  clock_.restart();
  statusBar()->showMessage(degrees > 0.f ? QString("Canvas tilted %1\u00b0 from the table").arg(double(degrees), 0, 'f', 0)
                                         : QString("Canvas flat on the table"),
                           5000);
}

void MainWindow::new_canvas(int width, int height, QColor paper, const CanvasGround& ground) {
  const Vec3 rgb(float(paper.redF()), float(paper.greenF()), float(paper.blueF()));
  sim_->post([width, height, rgb, ground](SimThread& s) {
    SimConfig c = s.config();
    c.canvas.width = width;
    c.canvas.height = height;
    s.renderer().params().paper_rgb = rgb;
    s.rebuild(c, false);
    if (ground.weave != Weave::Smooth) s.prime(ground);
    s.restart_recording(true);
  });
  clock_ = PenClock(width, height);
  undo_->clear();
  view_->set_canvas_size(width, height);
  path_.clear();
  dirty_ = false;
  update_title();
}

void MainWindow::settle(bool present) {
  while (present && !(sim_->is_idle() && palette_->sim()->is_idle())) {
    QCoreApplication::processEvents(QEventLoop::AllEvents, 5);
    QThread::usleep(500);
  }
  for (int pass = 0; pass < 2; ++pass) {
    sim_->wait_idle();
    palette_->sim()->wait_idle();
    QCoreApplication::processEvents();
  }
}

bool MainWindow::write_snapshot(const QString& path, bool wait, bool user_save) {
  // The snapshot is taken on the simulation thread between two steps (a copy of the tiles and
  // the rendered image); the file is written on a pool thread, so painting goes on.
  auto done = std::make_shared<std::promise<std::string>>();
  std::future<std::string> result = done->get_future();
  const std::string file = path.toStdString();
  const bool from_blank = sim_->recording_from_blank();
  ++saves_in_flight_;
  const int64_t serial = ++snapshot_serial_;
  if (!user_save) autosave_serial_ = serial;
  // The palette at rest, copied on its own thread; posted with the canvas's snapshot, so the
  // canvas's thread waits for it only behind what was asked of the palette before (a carry of
  // the brush that the canvas's thread itself serves first).
  using Snapshot = std::shared_ptr<const PaintingSnapshot>;
  auto palette_copy = std::make_shared<std::promise<Snapshot>>();
  std::shared_future<Snapshot> palette = palette_copy->get_future().share();
  palette_->sim()->post([palette_copy](SimThread& s) {
    try {
      const Image unrendered;  // the palette's picture is not saved
      palette_copy->set_value(std::make_shared<const PaintingSnapshot>(s.session().snapshot({}, &unrendered)));
    } catch (...) {
      palette_copy->set_exception(std::current_exception());
    }
  });
  sim_->post([done, file, from_blank, palette](SimThread& s) {
    try {
      // The paint at rest, with what is in flight now; the simulation goes on unchanged.
      const Image image = s.canvas_image();
      auto snap = std::make_shared<const PaintingSnapshot>(
          s.session().snapshot({{"generator", "wetbrush-studio"}, {"recording_from_blank", from_blank}}, &image));
      Snapshot pal = palette.get();
      QThreadPool::globalInstance()->start([done, file, snap, pal] {
        try {
          write_painting(file, *snap, pal.get());
          done->set_value("");
        } catch (const std::exception& e) {
          done->set_value(user_message(e));
        }
      });
    } catch (const std::exception& e) {
      done->set_value(user_message(e));
    }
  });
  // A user save marks the painting saved at once (strokes painted while the file is written
  // are changes after it), and takes that back if the write fails: the painting stays open
  // and unsaved, with its previous file name.
  const QString previous_path = path_;
  const auto finish = [this, path, user_save, previous_path, serial](const std::string& err) {
    --saves_in_flight_;
    if (!err.empty()) {
      const QString msg = QString::fromStdString(err);
      std::fprintf(stderr, "wetbrush-studio: %s\n", qPrintable(msg));
      autosave_due_ = true;
      if (!user_save) {
        // An autosave retries on its timer; a dialog would interrupt the stroke being painted.
        statusBar()->showMessage("Autosave failed: " + msg, 10000);
        return false;
      }
      undo_->resetClean();
      dirty_ = true;
      if (path_ == path) path_ = previous_path;
      update_title();
      QMessageBox::warning(this, "Save failed",
                           msg + "\n\nThe painting is still open with its unsaved changes. Save it again, "
                                 "or to another folder.");
      return false;
    }
    if (user_save) {
      add_recent(path);
      statusBar()->showMessage("Saved " + path, 4000);
      saved_serial_ = std::max(saved_serial_, serial);
    }
    // A recovery file older than a saved painting would offer, after a crash, to go back to
    // before the save: it goes (an autosave asked for later is newer and stays).
    if (autosave_serial_ < saved_serial_) QFile::remove(recovery_path());
    return true;
  };
  if (user_save) {
    path_ = path;
    undo_->setClean();
    dirty_ = false;
    update_title();
  }
  if (wait) return finish(result.get());
  auto shared = std::make_shared<std::future<std::string>>(std::move(result));
  auto* poll = new QTimer(this);
  poll->setInterval(50);
  connect(poll, &QTimer::timeout, this, [poll, shared, finish] {
    if (shared->wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    poll->stop();
    poll->deleteLater();
    finish(shared->get());
  });
  poll->start();
  return true;
}

void MainWindow::wait_for_saves() {
  while (saves_in_flight_ > 0)
    QCoreApplication::processEvents(QEventLoop::WaitForMoreEvents | QEventLoop::ExcludeUserInputEvents);
}

bool MainWindow::save_to(const QString& path, bool wait) { return write_snapshot(path, wait, true); }

bool MainWindow::open_from(const QString& path) {
  auto done = std::make_shared<std::promise<std::string>>();
  auto dims = std::make_shared<CanvasDims>();
  const std::string file = path.toStdString();
  PalettePanel* palette = palette_;
  sim_->post([done, dims, file, palette](SimThread& s) {
    try {
      s.open(file, false);
      // The painting's palette replaces the one on the desk (its own size, if it was saved with
      // another preset's).
      palette->sim()->post([file, palette](SimThread& ps) {
        const CanvasDims before = ps.session().dims();
        if (!ps.open(file, true)) return;
        const CanvasDims d = ps.session().dims();
        if (!(d == before))
          QMetaObject::invokeMethod(palette, [palette, w = d.width, h = d.height] { palette->set_canvas_size(w, h); },
                                    Qt::QueuedConnection);
      });
      const CanvasDims c{s.session().dims()};
      *dims = c;
      done->set_value("");
    } catch (const std::exception& e) {
      done->set_value(user_message(e));
    }
  });
  const std::string err = done->get_future().get();
  if (!err.empty()) {
    QMessageBox::warning(this, "Open failed", QString::fromStdString(err));
    return false;
  }
  clock_ = PenClock(dims->width, dims->height);
  view_->set_canvas_size(dims->width, dims->height);
  undo_->clear();
  path_ = path;
  dirty_ = false;
  add_recent(path);
  update_title();
  return true;
}

bool MainWindow::run_export(std::function<void(SimThread&)> write) {
  auto done = std::make_shared<std::promise<std::string>>();
  sim_->post([done, write = std::move(write)](SimThread& s) {
    try {
      write(s);
      done->set_value("");
    } catch (const std::exception& e) {
      done->set_value(user_message(e));
    }
  });
  const std::string err = done->get_future().get();
  if (!err.empty()) QMessageBox::warning(this, "Export failed", QString::fromStdString(err));
  return err.empty();
}

bool MainWindow::export_png(const QString& path) {
  return run_export([file = path.toStdString()](SimThread& s) {
    const Image img = s.canvas_image();
    write_png8(file, img.rgba.data(), img.width, img.height, 4);
  });
}

bool MainWindow::export_maps(const QString& height_path, const QString& normal_path) {
  return run_export([hp = height_path.toStdString(), np = normal_path.toStdString()](SimThread& s) {
    s.session().export_maps(MaterialMapPaths{hp, np, ""});
  });
}

#if WB_WITH_MEDIA
bool MainWindow::export_relief(const QString& exr_path, const QString& stl_path, const QString& glb_path) {
  return run_export([paths = ReliefPaths{exr_path.toStdString(), stl_path.toStdString(), glb_path.toStdString()}](
                        SimThread& s) {
    write_relief_exports(s.session(), paths);
  });
}

bool MainWindow::export_timelapse(const QString& path, const TimelapseOptions& options) {
  Stroke rec = sim_->recording();
  if (rec.samples.empty()) {
    QMessageBox::warning(this, "Export failed", "Nothing painted since the recording started: no time-lapse to make");
    return false;
  }
  // The replay runs as `wetbrush replay` would, with the studio's parameters and view.
  auto got = std::make_shared<std::promise<std::pair<SimConfig, RenderParams>>>();
  sim_->post([got](SimThread& s) { got->set_value({s.config(), s.renderer().params()}); });
  auto [config, render] = got->get_future().get();
  config.canvas = rec.canvas;
  config.brush = rec.brush;
  if (rec.window) config.window = Int3{(*rec.window)[0], (*rec.window)[1], std::min((*rec.window)[2], rec.canvas.depth)};
  config.params.render = render;
  std::atomic<int64_t> done{0}, total{1};
  std::atomic<bool> cancel{false};
  const std::string file = path.toStdString();
  auto job = std::async(std::launch::async, [&]() -> std::string {
    try {
      write_timelapse(rec, config, file, options, [&](int64_t d, int64_t t) {
        done = d, total = std::max<int64_t>(t, 1);
        return !cancel.load();
      });
      return "";
    } catch (const std::exception& e) {
      return user_message(e);
    }
  });
  QProgressDialog progress("Replaying the session into a time-lapse...", "Cancel", 0, 1000, this);
  progress.setWindowModality(Qt::WindowModal);
  progress.setMinimumDuration(500);
  while (job.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
    progress.setValue(int(1000 * done.load() / total.load()));
    QApplication::processEvents();
    if (progress.wasCanceled()) cancel = true;
  }
  progress.reset();
  const std::string err = job.get();
  if (!err.empty() && !cancel) QMessageBox::warning(this, "Export failed", QString::fromStdString(err));
  if (err.empty() && !sim_->recording_from_blank())
    statusBar()->showMessage("Time-lapse written; the recording started on a painted canvas (after undo, open or a "
                             "brush change), so it shows only the strokes since then",
                             8000);
  return err.empty();
}
#endif

bool MainWindow::save_recording(const QString& path) {
  try {
    Stroke rec = sim_->recording();
    if (rec.samples.empty()) WB_THROW("nothing painted since the recording started");
    save_stroke_json(rec, path.toStdString());
    if (!sim_->recording_from_blank())
      statusBar()->showMessage("Recording saved; it started on a painted canvas (after undo, open or a brush "
                               "change), so a replay on a blank canvas shows only the strokes since then",
                               8000);
    return true;
  } catch (const std::exception& e) {
    QMessageBox::warning(this, "Save recording failed", QString::fromStdString(user_message(e)));
    return false;
  }
}

void MainWindow::update_status() {
  const SimStatus st = sim_->status();
  const double now = wall_now();
  if (frames_t_ > 0) view_fps_ = (view_->frames_drawn() - frames_at_) / std::max(1e-3, now - frames_t_);
  frames_at_ = view_->frames_drawn();
  frames_t_ = now;
  QString sim = QString("Sim %1 steps/s (%2 ms/step)").arg(st.steps_per_s, 0, 'f', 1).arg(st.step_ms, 0, 'f', 1);
  if (st.lag_s > 0.05) sim += QString(", %1 s behind").arg(st.lag_s, 0, 'f', 1);
  sim += st.particles >= 0 ? QString(" \u00b7 %1 particles").arg(st.particles) : QString(" \u00b7 particles: n/a");
  if (!st.error.empty()) sim += " \u00b7 STOPPED: " + QString::fromStdString(st.error);
  status_sim_->setText(sim);
  // The surface the brush is on: its pen-to-paint latency, and whether its simulation keeps up.
  CanvasView* painted = brush_on_palette_ ? palette_->view() : view_;
  const SimStatus ps = brush_on_palette_ ? palette_->sim()->status() : st;
  const double latency = painted->latency().current_ms(now);
  status_view_->setText(QString("View %1 fps \u00b7 %2 \u00b7 latency %3 \u00b7 %4% \u00b7 %5\u00b0")
                            .arg(view_fps_, 0, 'f', 0)
                            .arg(view_kind_name(view_->kind()))
                            .arg(latency >= 0 ? QString("%1 ms").arg(latency, 0, 'f', 0) : QString("\u2013"))
                            .arg(view_->zoom() * 100.f, 0, 'f', 0)
                            .arg(view_->rotation_deg(), 0, 'f', 0));
  if (ps.realtime_factor >= 0.0 && ps.realtime_factor < 1.0) {
    QString behind = QString("Behind real time: %1\u00d7 over the last second").arg(ps.realtime_factor, 0, 'f', 2);
    if (const auto lighter = lighter_preset_that_keeps_up(ps.brush_samples, ps.window, ps.realtime_factor))
      behind += QString("; the %1 preset keeps up (--preset %2)")
                    .arg(QString::fromStdString(lighter->name), QString::fromStdString(lighter->id));
    else
      behind += "; no lighter preset keeps up";
    status_behind_->setText(behind);
    status_behind_->show();
  } else {
    status_behind_->hide();
  }
  status_device_->setText(QString("Device %1 \u00b7 Preset %2")
                              .arg(QString::fromStdString(st.device), QString::fromStdString(options_.preset.name)));
  SimThread* holder = brush_on_palette_ ? palette_->sim() : sim_.get();
  const SimStatus hs = brush_on_palette_ ? holder->status() : st;
  paint_panel_->show_brush(hs.brush_ryb, hs.brush_amount);
  if (brush_preview_->isVisible()) brush_preview_->set_picture(holder->brush_picture());
}

void MainWindow::update_title() {
  const QString name = path_.isEmpty() ? "Untitled" : QFileInfo(path_).fileName();
  setWindowTitle(QString("%1%2 \u2014 wetbrush studio").arg(name, modified() ? " *" : ""));
}

void MainWindow::add_recent(const QString& path) {
  QSettings s(options_.data_dir + "/studio.ini", QSettings::IniFormat);
  QStringList list = s.value("recent").toStringList();
  list.removeAll(path);
  list.prepend(path);
  while (list.size() > 8) list.removeLast();
  s.setValue("recent", list);
  rebuild_recent_menu();
}

void MainWindow::ask_memory_limit() {
  const size_t now = wb::mem::budget(false);
  bool ok = false;
  const QString text = QInputDialog::getText(
      this, "Memory limit",
      "Most memory the paintings may hold, host and GPU each (e.g. 4G, 512M; empty: what the machine has).\n"
      "A canvas or preset larger than this is refused with the memory it needs.",
      QLineEdit::Normal, now ? QString::fromStdString(wb::mem::format_bytes(double(now))).remove(' ').remove("i") : "",
      &ok);
  if (!ok) return;
  const QString t = text.trimmed();
  try {
    if (t.isEmpty()) {
      wb::mem::set_budget(false, 0);
      wb::mem::set_budget(true, 0);
    } else {
      wb::mem::set_budget_from(t.toStdString());
    }
  } catch (const std::exception& e) {
    QMessageBox::warning(this, "Memory limit", QString::fromStdString(wb::user_message(e)));
    return;
  }
  QSettings(options_.data_dir + "/studio.ini", QSettings::IniFormat).setValue("memory_limit", t);
  statusBar()->showMessage(t.isEmpty() ? "Memory limit: what the machine has" : "Memory limit: " + t, 5000);
}

void MainWindow::rebuild_recent_menu() {
  if (!recent_menu_) return;
  recent_menu_->clear();
  QSettings s(options_.data_dir + "/studio.ini", QSettings::IniFormat);
  for (const QString& p : s.value("recent").toStringList())
    recent_menu_->addAction(p, this, [this, p] {
      if (maybe_save()) open_from(p);
    });
  recent_menu_->setEnabled(!recent_menu_->isEmpty());
}

bool MainWindow::maybe_save() {
  // A save still being written may fail and leave the painting unsaved after all.
  wait_for_saves();
  if (!modified()) return true;
  const auto b = QMessageBox::question(this, "Unsaved changes", "The painting has unsaved changes. Save them?",
                                       QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel,
                                       QMessageBox::Save);
  if (b == QMessageBox::Cancel) return false;
  if (b == QMessageBox::Save) {
    QString p = path_;
    if (p.isEmpty()) p = QFileDialog::getSaveFileName(this, "Save painting", "painting.ora", "OpenRaster (*.ora)");
    if (p.isEmpty()) return false;
    return save_to(p, true);
  }
  return true;
}

void MainWindow::autosave() {
  if (!autosave_due_ && !dirty_) return;
  if (!modified()) return;
  autosave_due_ = false;
  write_snapshot(recovery_path(), false, false);
}

void MainWindow::check_recovery() {
  if (!QFile::exists(recovery_path())) return;
  const auto b = QMessageBox::question(
      this, "Recover painting", "wetbrush studio did not close normally. Recover the last autosaved painting?",
      QMessageBox::Yes | QMessageBox::No, QMessageBox::Yes);
  if (b == QMessageBox::Yes && open_from(recovery_path())) {
    path_.clear();
    dirty_ = true;
    update_title();
  } else {
    QFile::remove(recovery_path());
  }
}

void MainWindow::closeEvent(QCloseEvent* e) {
  if (!maybe_save()) {
    e->ignore();
    return;
  }
  QThreadPool::globalInstance()->waitForDone();
  QFile::remove(recovery_path());
  e->accept();
}

}  // namespace wb::studio
