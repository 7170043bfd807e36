// The studio's access to the canvas between steps: flushing the window, the settled canvas
// for files, exports and undo, dropping paint in flight and reloading the window after tiles
// were written from outside. (Steps and palette events go through core/sim/replay's drive_step,
// as in `wetbrush replay`, so that a session and the replay of its recording do the same things.)
#pragma once
#include <cstdint>
#include <functional>

#include "core/io/stroke.h"
#include "core/sim/simulator.h"

namespace wb::studio {

/// Writes the live window back to the canvas tiles without changing the simulation (its next
/// scatter overwrites the same cells with its own values). Paint in flight (particles) is not
/// on the tiles: see with_settled_canvas.
void flush_simulation(Simulator& sim);
/// Runs `fn` on the canvas as it is when every paint comes to rest now: Simulator::settle
/// (particles back into the grid by Eq. 16, the window written to the tiles). Then puts the
/// simulation back as it was (window, particles and the tiles under the window), so a session
/// that saves replays like one that does not. Files, exports and undo records see this canvas.
void with_settled_canvas(Simulator& sim, const std::function<void(TileStore&)>& fn);
/// A copy of the settled canvas (on `device`, default the host), without tiles that are all zero.
TileStore settled_canvas_copy(Simulator& sim, const Device& device = Device{});
/// Drops the paint in flight (undo and redo replace the canvas the particles belonged to).
void drop_particles(Simulator& sim);
/// Reads the live window back from the tiles after they were written from outside
/// (undo, redo, open, a new simulator on a kept canvas).
void reload_window(Simulator& sim);
/// Liquid particles in flight (-1 when the simulator has none).
int64_t particle_count(Simulator& sim);

}  // namespace wb::studio
