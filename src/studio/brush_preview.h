// The brush preview: the simulated bristles of the current brush as they are now, seen from
// the side (against the canvas line) and from below (where they touch), each bristle in the
// colour of the paint it holds. Fed from SimThread::brush_picture with every rendered frame.
#pragma once
#include <QWidget>

#include "core/sim/simulator.h"

namespace wb::studio {

class BrushPreview : public QWidget {
  Q_OBJECT
 public:
  explicit BrushPreview(QWidget* parent = nullptr);
  void set_picture(BrushPicture picture);
  const BrushPicture& picture() const { return picture_; }
  /// Bristle vertices within a cell of the canvas in the last picture.
  int touching() const { return touching_; }
  QSize sizeHint() const override { return QSize(260, 130); }

 protected:
  void paintEvent(QPaintEvent* e) override;

 private:
  BrushPicture picture_;
  int touching_ = 0;
};

}  // namespace wb::studio
