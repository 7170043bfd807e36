// The studio's undo records: before every step, the tiles that step may change (the brush's
// reach and the active window around the pen at its start and end) that are not captured yet;
// after a stroke, when the simulation is idle, the tiles that changed, before and after, against
// the canvas with its paint at rest (docs/STUDIO.md "Undo"). Simulation thread only.
#pragma once
#include <memory>

#include "core/io/undo_tiles.h"
#include "core/sim/simulator.h"

namespace wb::studio {

class StrokeUndo {
 public:
  /// Before a step from pen `a` to pen `b`: captures the tiles it may touch. Every step belongs
  /// to the record of the stroke it leads to: the steps between two strokes (the lifted brush
  /// moving on, paint in flight landing) change tiles too.
  void before_step(Simulator& sim, const PenSample& a, const PenSample& b);
  /// The stroke is over: its record (null when none is open or nothing changed). The tiles under
  /// the window, at rest now, start the next record, so that its undo returns to this canvas.
  std::shared_ptr<TileDiff> finish(Simulator& sim);
  /// The stroke cannot be finished (a step failed): the tiles it may have touched as they were
  /// before it, read from the record alone; no record is open.
  std::vector<TileSnapshot> abandon() {
    open_ = false;
    return rec_.take_before();
  }
  /// The canvas was written from outside: no record is open.
  void reset() {
    rec_.reset();
    open_ = false;
  }

 private:
  StrokeTileRecorder rec_;
  bool open_ = false;
};

}  // namespace wb::studio
