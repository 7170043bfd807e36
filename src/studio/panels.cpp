#include "studio/panels.h"

#include <QButtonGroup>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QInputDialog>
#include <QLabel>
#include <QMessageBox>
#include <QPushButton>
#include <QSlider>
#include <QSpinBox>
#include <QToolButton>
#include <QVBoxLayout>

#include <nlohmann/json.hpp>

#include "core/color/ryb.h"
#include "core/io/atomic_file.h"
#include "core/exec/error.h"
#include "core/io/brush_json.h"

namespace wb::studio {

QColor ryb_to_qcolor(const std::array<float, 3>& ryb) {
  const Vec3 c = ryb_to_rgb(Vec3(ryb[0], ryb[1], ryb[2]));
  return QColor::fromRgbF(std::clamp(c.x, 0.f, 1.f), std::clamp(c.y, 0.f, 1.f), std::clamp(c.z, 0.f, 1.f));
}

std::array<float, 3> qcolor_to_ryb(const QColor& c) {
  const Vec3 r = rgb_to_ryb(Vec3(float(c.redF()), float(c.greenF()), float(c.blueF())));
  return {r.x, r.y, r.z};
}

// --- brush ------------------------------------------------------------------------------

namespace {
const BrushShape kShapes[] = {BrushShape::Round,   BrushShape::Flat,  BrushShape::Fan,   BrushShape::Filbert,
                              BrushShape::Angular, BrushShape::Mop,   BrushShape::Rigger};

QDoubleSpinBox* spin(double lo, double hi, double step, int decimals, const QString& tip) {
  auto* s = new QDoubleSpinBox;
  s->setRange(lo, hi);
  s->setSingleStep(step);
  s->setDecimals(decimals);
  s->setToolTip(tip);
  s->setKeyboardTracking(false);
  return s;
}

/// The tooltip of a brush field: what it does, its range and unit, its place in the paper.
QString brush_tip(const BrushFieldRange& f) {
  QString t = QString::fromUtf8(f.tooltip) + QString(" (%1 to %2").arg(f.min).arg(f.max);
  if (*f.unit) t += " " + QString::fromUtf8(f.unit);
  t += ")";
  if (*f.paper) t += ", " + QString::fromUtf8(f.paper);
  return t;
}

/// A spin box for a brush field, its range and tooltip from the brush table (brush_json.h);
/// named by the field's key.
QDoubleSpinBox* brush_spin(const char* key, double step, int decimals) {
  const BrushFieldRange& f = brush_field(key);
  QDoubleSpinBox* s = spin(f.min, f.max, step, decimals, brush_tip(f));
  s->setObjectName(QString::fromUtf8(key));
  return s;
}
}  // namespace

BrushPanel::BrushPanel(QWidget* parent) : QWidget(parent) {
  auto* form = new QFormLayout(this);
  shape_ = new QComboBox;
  for (BrushShape s : kShapes) shape_->addItem(QString::fromUtf8(to_string(s)));
  shape_->setToolTip("Bristle bundle shape (default sizes per shape: docs/FORMATS.md)");
  size_ = brush_spin("width", 2, 0);
  const BrushFieldRange& nb = brush_field("bristles");
  bristles_ = new QSpinBox;
  bristles_->setObjectName("bristles");
  bristles_->setRange(int(nb.min), int(nb.max));
  bristles_->setToolTip(brush_tip(nb));
  bristles_->setKeyboardTracking(false);
  stiffness_ = brush_spin("stiffness", 0.05, 2);
  length_ = brush_spin("length", 5, 0);
  beta_ = brush_spin("beta_B", 0.01, 3);
  presets_ = new QComboBox;
  auto* save = new QPushButton("Save preset...");
  form->addRow("Shape", shape_);
  for (QWidget* w : std::initializer_list<QWidget*>{size_, bristles_, stiffness_, length_, beta_})
    form->addRow(QString::fromUtf8(brush_field(w->objectName().toStdString()).label), w);
  form->addRow("Preset", presets_);
  form->addRow(save);

  connect(shape_, &QComboBox::currentIndexChanged, this, [this](int i) {
    if (updating_) return;
    // A new shape starts from that shape's defaults, keeping the bristle count.
    BrushSpec b = default_brush(kShapes[i]);
    b.bristles = bristles_->value();
    b.samples_per_bristle = base_.samples_per_bristle;
    set_brush(b);
    emit_changed();
  });
  for (auto* s : {size_, stiffness_, length_, beta_})
    connect(s, &QDoubleSpinBox::valueChanged, this, [this] { emit_changed(); });
  connect(bristles_, &QSpinBox::valueChanged, this, [this] { emit_changed(); });
  connect(presets_, &QComboBox::activated, this, [this](int i) {
    const QString path = presets_->itemData(i).toString();
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) return;
    try {
      BrushSpec b = brush_from_json(nlohmann::json::parse(f.readAll().toStdString()), path.toStdString(), "");
      set_brush(b);
      emit_changed();
    } catch (const std::exception& e) {
      QMessageBox::warning(this, "Brush preset", QString::fromStdString(user_message(e)));
    }
  });
  connect(save, &QPushButton::clicked, this, [this] {
    if (preset_dir_.isEmpty()) return;
    bool ok = false;
    const QString name = QInputDialog::getText(this, "Save brush preset", "Name:", QLineEdit::Normal, "", &ok);
    if (!ok || name.trimmed().isEmpty()) return;
    QDir().mkpath(preset_dir_);
    try {
      write_file_atomic((preset_dir_ + "/" + name.trimmed() + ".json").toStdString(),
                        brush_to_json(brush()).dump(2) + "\n");
    } catch (const std::exception& e) {
      QMessageBox::warning(this, "Save brush preset", QString::fromStdString(user_message(e)));
      return;
    }
    reload_presets();
  });
}

void BrushPanel::set_preset_dir(const QString& dir) {
  preset_dir_ = dir;
  reload_presets();
}

void BrushPanel::reload_presets() {
  presets_->clear();
  for (const QFileInfo& fi : QDir(preset_dir_).entryInfoList({"*.json"}, QDir::Files, QDir::Name))
    presets_->addItem(fi.completeBaseName(), fi.absoluteFilePath());
}

BrushSpec BrushPanel::brush() const {
  BrushSpec b = base_;
  b.shape = kShapes[shape_->currentIndex()];
  const float scale = float(size_->value()) / std::max(1.f, base_.width);
  b.width = float(size_->value());
  b.thickness = base_.thickness * scale;
  b.bristles = bristles_->value();
  b.stiffness = float(stiffness_->value());
  b.length = float(length_->value());
  b.beta_B = float(beta_->value());
  return b;
}

void BrushPanel::set_brush(const BrushSpec& b) {
  updating_ = true;
  base_ = b;
  for (int i = 0; i < 7; ++i)
    if (kShapes[i] == b.shape) shape_->setCurrentIndex(i);
  size_->setValue(b.width);
  bristles_->setValue(b.bristles);
  stiffness_->setValue(b.stiffness);
  length_->setValue(b.length);
  beta_->setValue(b.beta_B);
  updating_ = false;
}

void BrushPanel::emit_changed() {
  if (updating_) return;
  const BrushSpec b = brush();
  base_ = b;
  Q_EMIT brushChanged(b);
}

// --- paint ------------------------------------------------------------------------------

PaintPanel::PaintPanel(QWidget* parent) : QWidget(parent) {
  auto* v = new QVBoxLayout(this);
  auto* grid = new QGridLayout;
  const std::array<float, 3> defaults[] = {{0.1f, 0.15f, 0.85f}, {0.9f, 0.1f, 0.f},  {0.05f, 0.9f, 0.f},
                                           {0.f, 0.f, 0.f},      {0.7f, 0.7f, 0.7f}, {0.5f, 0.9f, 0.1f},
                                           {0.1f, 0.8f, 0.8f},   {0.6f, 0.2f, 0.6f}};
  auto* group = new QButtonGroup(this);
  for (int i = 0; i < 8; ++i) {
    auto* b = new QToolButton;
    b->setCheckable(true);
    b->setFixedSize(34, 34);
    b->setToolTip("Paint well: click to select, double-click or right-click to pick its colour");
    b->setContextMenuPolicy(Qt::CustomContextMenu);
    group->addButton(b, i);
    grid->addWidget(b, i / 4, i % 4);
    wells_.push_back(b);
    ryb_.push_back(defaults[i]);
    connect(b, &QToolButton::clicked, this, [this, i] { select(i); });
    connect(b, &QToolButton::customContextMenuRequested, this, [this, i] {
      const QColor c = QColorDialog::getColor(well_color(i), this, "Paint well colour");
      if (c.isValid()) set_well_color(i, c);
    });
  }
  for (int i = 0; i < 8; ++i) set_well_color(i, ryb_to_qcolor(ryb_[i]));
  for (int i = 0; i < 8; ++i) ryb_[i] = defaults[i];
  v->addLayout(grid);
  auto* form = new QFormLayout;
  oil_ = new QSlider(Qt::Horizontal);
  oil_->setRange(0, 100);
  oil_->setValue(30);
  oil_->setToolTip("Oil fraction: more oil is runnier and more transparent");
  amount_ = new QSlider(Qt::Horizontal);
  amount_->setRange(5, 100);
  amount_->setValue(80);
  amount_->setToolTip("Dip fills the bristles to this fraction of their capacity");
  form->addRow("Oil", oil_);
  form->addRow("Amount", amount_);
  v->addLayout(form);
  auto* buttons = new QHBoxLayout;
  auto* dip_b = new QPushButton("Dip");
  dip_b->setToolTip("Load the brush from the selected well (D)");
  auto* wipe_b = new QPushButton("Wipe");
  wipe_b->setToolTip("Wipe half of the paint off the brush (W)");
  auto* clean_b = new QPushButton("Clean");
  clean_b->setToolTip("Clean the brush in solvent (C)");
  buttons->addWidget(dip_b);
  buttons->addWidget(wipe_b);
  buttons->addWidget(clean_b);
  v->addLayout(buttons);
  reload_ = new QCheckBox("Reload each stroke");
  reload_->setChecked(true);
  reload_->setToolTip("On: each stroke starts with a clean brush loaded from the selected well.\n"
                      "Off: the brush keeps its paint from stroke to stroke; Dip, Wipe and Clean change it.");
  v->addWidget(reload_);
  connect(reload_, &QCheckBox::toggled, this, [this](bool on) { Q_EMIT reloadToggled(on); });
  auto* row = new QHBoxLayout;
  row->addWidget(new QLabel("Brush:"));
  brush_swatch_ = new QLabel;
  brush_swatch_->setFixedSize(120, 24);
  brush_swatch_->setToolTip("Paint on the brush: its mixed colour, and how full it is");
  row->addWidget(brush_swatch_);
  row->addStretch();
  v->addLayout(row);
  v->addStretch();
  connect(dip_b, &QPushButton::clicked, this, [this] { Q_EMIT dip(current_paint()); });
  connect(wipe_b, &QPushButton::clicked, this, [this] { Q_EMIT wipe(0.5f); });
  connect(clean_b, &QPushButton::clicked, this, [this] { Q_EMIT clean(); });
  select(0);
  show_brush(ryb_[0], 0.f);
}

bool PaintPanel::reload_each_stroke() const { return reload_->isChecked(); }

void PaintPanel::set_reload_each_stroke(bool on) { reload_->setChecked(on); }

void PaintPanel::select(int i) {
  current_ = i;
  wells_[size_t(i)]->setChecked(true);
}

QColor PaintPanel::well_color(int i) const { return ryb_to_qcolor(ryb_[size_t(i)]); }

void PaintPanel::set_well_color(int i, const QColor& c) { set_well_ryb(i, qcolor_to_ryb(c)); }

void PaintPanel::set_well_ryb(int i, const std::array<float, 3>& ryb) {
  ryb_[size_t(i)] = ryb;
  const QColor shown = ryb_to_qcolor(ryb_[size_t(i)]);
  wells_[size_t(i)]->setStyleSheet(QString("QToolButton { background: %1; border: 2px solid #444; border-radius: 17px; }"
                                           "QToolButton:checked { border: 3px solid #fff; }")
                                       .arg(shown.name()));
}

PaintLoad PaintPanel::current_paint() const {
  PaintLoad p;
  for (int c = 0; c < 3; ++c) p.ryb[c] = ryb_[size_t(current_)][c];
  p.oil = oil_->value() / 100.f;
  p.load = amount_->value() / 100.f;
  p.reload_on_pen_down = false;
  return p;
}

void PaintPanel::show_brush(const std::array<float, 3>& ryb, float amount) {
  const QColor c = amount > 0.f ? ryb_to_qcolor(ryb) : QColor(230, 226, 215);
  const int w = int(std::round(std::clamp(amount, 0.f, 1.f) * 100));
  brush_swatch_->setStyleSheet(
      QString("QLabel { border: 1px solid #333; background: qlineargradient(x1:0, y1:0, x2:1, y2:0, stop:0 %1, "
              "stop:%2 %1, stop:%3 #ddd, stop:1 #ddd); }")
          .arg(c.name())
          .arg(std::max(0.0, w / 100.0 - 0.001))
          .arg(w / 100.0));
  brush_swatch_->setText(QString("  %1%").arg(w));
}

// --- view -------------------------------------------------------------------------------

ViewPanel::ViewPanel(QWidget* parent) : QWidget(parent) {
  auto* form = new QFormLayout(this);
  auto slider = [&](int lo, int hi, int v, const QString& tip) {
    auto* s = new QSlider(Qt::Horizontal);
    s->setRange(lo, hi);
    s->setValue(v);
    s->setToolTip(tip);
    return s;
  };
  azimuth_ = slider(0, 359, 231, "Direction the light comes from, degrees");
  elevation_ = slider(5, 90, 50, "Height of the light above the canvas, degrees (low light shows relief)");
  relief_ = slider(0, 100, 65, "Strength of the relief shading");
  mouse_pressure_ = slider(0, 100, 50, "Pressure of the mouse (a tablet gives its own)");
  gamma_ = slider(30, 300, 100, "Pressure curve: output = input ^ (value / 100)");
  azimuth_->setObjectName("light_azimuth");
  elevation_->setObjectName("light_elevation");
  auto* rake_b = new QPushButton("Raking light");
  rake_b->setObjectName("rake");
  rake_b->setToolTip("Light low across the canvas (12 degrees), to judge the relief. Drag on the canvas with "
                     "the right button to move the light");
  oblique_ = new QCheckBox("Oblique view");
  oblique_->setObjectName("oblique");
  oblique_->setToolTip("The whole canvas seen from 30 degrees above, under the same light, in its own panel");
  form->addRow("Light direction", azimuth_);
  form->addRow("Light height", elevation_);
  form->addRow("Relief", relief_);
  form->addRow(rake_b, oblique_);
  form->addRow("Mouse pressure", mouse_pressure_);
  form->addRow("Pressure curve", gamma_);
  for (QSlider* s : {azimuth_, elevation_, relief_}) connect(s, &QSlider::sliderReleased, this, [this] { emit_lighting(); });
  connect(rake_b, &QPushButton::clicked, this, [this] { rake(); });
  connect(oblique_, &QCheckBox::toggled, this, [this](bool on) { Q_EMIT obliqueToggled(on); });
  for (QSlider* s : {mouse_pressure_, gamma_})
    connect(s, &QSlider::valueChanged, this,
            [this] { Q_EMIT pressureChanged(mouse_pressure_->value() / 100.f, gamma_->value() / 100.f); });
}

float ViewPanel::azimuth() const { return float(azimuth_->value()); }
float ViewPanel::elevation() const { return float(elevation_->value()); }

void ViewPanel::emit_lighting() {
  Q_EMIT lightingChanged(float(azimuth_->value()), float(elevation_->value()), relief_->value() / 100.f);
}

void ViewPanel::set_light(float azimuth_deg, float elevation_deg, bool apply) {
  const float a = std::fmod(std::fmod(azimuth_deg, 360.f) + 360.f, 360.f);
  azimuth_->setValue(int(std::lround(a)) % 360);
  elevation_->setValue(std::clamp(int(std::lround(elevation_deg)), elevation_->minimum(), elevation_->maximum()));
  if (apply) emit_lighting();
}

void ViewPanel::rake() { set_light(azimuth(), 12.f, true); }

void ViewPanel::set_oblique(bool on) { oblique_->setChecked(on); }
bool ViewPanel::oblique() const { return oblique_->isChecked(); }

}  // namespace wb::studio
