// The studio's calls into the simulator's paint API (paper §5: the brush's load; dip, wipe,
// clean; drying), in one place and in the same order as the replay driver (core/sim/replay),
// so that the live session and `wetbrush replay` of its recording do the same things.
#pragma once
#include <cstdint>

#include "core/io/stroke.h"
#include "core/sim/simulator.h"

namespace wb::studio {

/// Loads the brush with the recording's paint (start of a recording, pen-down reloads).
void apply_initial_paint(Simulator& sim, const PaintLoad& paint);
/// A palette event: dip, wipe, clean or dry.
void apply_paint_event(Simulator& sim, const StrokeEvent& e);
/// Writes every live paint state (active window) back to the canvas tiles.
void flush_simulation(Simulator& sim);
/// Reads the live window back from the tiles after they were written from outside
/// (undo, redo, open, a new simulator on a kept canvas).
void reload_window(Simulator& sim);
/// Liquid particles in flight (-1 when the simulator has none).
int64_t particle_count(Simulator& sim);

}  // namespace wb::studio
