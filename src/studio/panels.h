// Side panels of the studio: the brush (shape, size, bristles, stiffness, length, beta_B,
// saved presets), the paint (palette wells stored as RYB, oil, amount, dip / wipe / clean,
// the brush's current colour and load) and the view (relief and lighting). Widgets only:
// they emit values, the main window passes them to the simulation thread.
#pragma once
#include <QColor>
#include <QWidget>

#include <array>
#include <vector>

#include "core/brush/brush_spec.h"
#include "core/io/stroke.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QSpinBox;
class QSlider;
class QLabel;
class QToolButton;
class QButtonGroup;
class QCheckBox;

namespace wb::studio {

class BrushPanel : public QWidget {
  Q_OBJECT
 public:
  explicit BrushPanel(QWidget* parent = nullptr);
  BrushSpec brush() const;
  void set_brush(const BrushSpec& b);
  /// Folder of saved presets (*.json, brush_json format).
  void set_preset_dir(const QString& dir);

 Q_SIGNALS:
  void brushChanged(wb::BrushSpec brush);

 private:
  void reload_presets();
  void emit_changed();
  BrushSpec base_{};
  QString preset_dir_;
  QComboBox* shape_ = nullptr;
  QComboBox* presets_ = nullptr;
  QDoubleSpinBox* size_ = nullptr;
  QSpinBox* bristles_ = nullptr;
  QDoubleSpinBox* stiffness_ = nullptr;
  QDoubleSpinBox* length_ = nullptr;
  QDoubleSpinBox* beta_ = nullptr;
  bool updating_ = false;
};

class PaintPanel : public QWidget {
  Q_OBJECT
 public:
  explicit PaintPanel(QWidget* parent = nullptr);
  /// The selected well as paint (RYB, oil, amount).
  PaintLoad current_paint() const;
  int current_well() const { return current_; }
  void set_well_color(int i, const QColor& c);
  /// Puts this pigment (RYB) in well i as it is (the eyedropper: no trip through RGB).
  void set_well_ryb(int i, const std::array<float, 3>& ryb);
  const std::array<float, 3>& well_ryb(int i) const { return ryb_[size_t(i)]; }
  QColor well_color(int i) const;
  int well_count() const { return int(wells_.size()); }
  /// Shows the brush's paint: mixed colour (RYB) and load in [0, 1].
  void show_brush(const std::array<float, 3>& ryb, float amount);
  /// On: every stroke on the canvas starts with a clean brush loaded from the selected well.
  /// Off: the brush keeps what it carries; Dip, Wipe and Clean change it.
  bool reload_each_stroke() const;
  void set_reload_each_stroke(bool on);

 Q_SIGNALS:
  void dip(wb::PaintLoad paint);
  void wipe(float fraction);
  void clean();
  void reloadToggled(bool on);

 private:
  void select(int i);
  std::vector<QToolButton*> wells_;
  std::vector<std::array<float, 3>> ryb_;
  int current_ = 0;
  QSlider* oil_ = nullptr;
  QSlider* amount_ = nullptr;
  QLabel* brush_swatch_ = nullptr;
  QCheckBox* reload_ = nullptr;
};

class ViewPanel : public QWidget {
  Q_OBJECT
 public:
  explicit ViewPanel(QWidget* parent = nullptr);
  float azimuth() const;
  float elevation() const;
  /// Moves the light (azimuth wraps, elevation clamps to the slider's 5..90 degrees); the
  /// sliders follow. `apply`: also emit lightingChanged (a drag applies once, when it ends).
  void set_light(float azimuth_deg, float elevation_deg, bool apply);
  /// Low light from the current direction, 12 degrees above the canvas: the relief in relief.
  void rake();
  void set_oblique(bool on);
  bool oblique() const;
 Q_SIGNALS:
  /// Light from `azimuth_deg` (0 = from +x, counter-clockwise), `elevation_deg` above the
  /// canvas; `relief` scales the diffuse term (0 flat .. 1 strong).
  void lightingChanged(float azimuth_deg, float elevation_deg, float relief);
  void pressureChanged(float mouse_pressure, float gamma);
  /// The oblique view (the whole canvas from 30 degrees above, in its own dock) on or off.
  void obliqueToggled(bool on);
 private:
  void emit_lighting();
  QSlider *azimuth_, *elevation_, *relief_, *mouse_pressure_, *gamma_;
  QCheckBox* oblique_ = nullptr;
};

/// Display colour of an RYB pigment (Gossett-Chen cube, core/color/ryb.h).
QColor ryb_to_qcolor(const std::array<float, 3>& ryb);
std::array<float, 3> qcolor_to_ryb(const QColor& c);

}  // namespace wb::studio
