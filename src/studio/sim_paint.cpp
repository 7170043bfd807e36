#include "studio/sim_paint.h"

namespace wb::studio {

// Same calls, same order as Replay (core/sim/replay.cpp): a recording replays the session.
void apply_initial_paint(Simulator& sim, const PaintLoad& paint) { sim.load_paint(paint); }

void apply_paint_event(Simulator& sim, const StrokeEvent& e) {
  PaintLoad well;
  switch (e.kind) {
    case StrokeEventKind::Dip:
      for (int c = 0; c < 3; ++c) well.ryb[c] = e.ryb[c];
      well.oil = e.oil;
      well.load = e.load;
      sim.dip(well);
      break;
    case StrokeEventKind::Wipe: sim.wipe(e.fraction); break;
    case StrokeEventKind::Clean: sim.clean(); break;
    case StrokeEventKind::Dry: sim.dry_canvas(); break;
  }
}

void flush_simulation(Simulator& sim) {
  // Writes the live window into the tiles without changing the simulation: the window keeps
  // its values, and its own next scatter overwrites the same cells.
  if (PaintWindow* w = sim.live_window()) sim.canvas().scatter(*w);
}

void reload_window(Simulator& sim) {
  if (PaintWindow* w = sim.live_window()) sim.canvas().gather(*w);
}

int64_t particle_count(Simulator& sim) { return sim.particles().size(); }

}  // namespace wb::studio
