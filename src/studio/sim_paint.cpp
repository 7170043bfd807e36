#include "studio/sim_paint.h"

#include <algorithm>
#include <vector>

#include "core/io/undo_tiles.h"

namespace wb::studio {

// Same calls, same order as Replay (core/sim/replay.cpp): a recording replays the session.
void flush_simulation(Simulator& sim) {
  // Writes the live window into the tiles without changing the simulation: the window keeps
  // its values, and its own next scatter overwrites the same cells.
  if (PaintWindow* w = sim.live_window()) sim.canvas().scatter(*w);
}

namespace {

/// Every particle field (state and scratch) on the host, for an exact restore.
struct ParticleCopy {
  int64_t count = 0;
#define WB_X(type, name, doc) std::vector<type> name;
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
};

ParticleCopy copy_particles(const ParticleStore& p) {
  ParticleCopy c;
  c.count = p.size();
#define WB_X(type, name, doc)      \
  c.name.resize(size_t(c.count)); \
  p.name.copy_to_host(c.name.data(), size_t(c.count));
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
  return c;
}

void restore_particles(ParticleStore& p, const ParticleCopy& c) {
  p.clear();
  p.append_uninitialised(c.count);
#define WB_X(type, name, doc) p.name.copy_range_from_host(c.name.data(), 0, size_t(c.count));
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
}

/// False for a tile that is all zero (as an undo writes back a tile that was never allocated).
bool tile_has_paint(const TileData& t) {
  const auto nonzero = [](const auto& v) { return std::any_of(v.begin(), v.end(), [](auto x) { return x != 0; }); };
  return nonzero(t.density) || nonzero(t.pigment_r) || nonzero(t.pigment_y) || nonzero(t.pigment_b) ||
         nonzero(t.oil) || nonzero(t.dryness);
}

}  // namespace

void with_settled_canvas(Simulator& sim, const std::function<void(TileStore&)>& fn) {
  PaintWindow* w = sim.live_window();
  TileStore& canvas = sim.canvas();
  if (!w || sim.particles().size() == 0) {  // nothing in flight: the flush is the settled canvas
    flush_simulation(sim);
    fn(canvas);
    return;
  }
  // settle() changes the window, the particles and the tiles under the window, nothing else.
  const std::vector<std::vector<float>> window = w->to_host();
  const ParticleCopy particles = copy_particles(sim.particles());
  std::vector<TileSnapshot> tiles;
  const Int3 o = w->origin(), n = w->dims();
  const int tx0 = std::max(0, o.x / kTileSize), ty0 = std::max(0, o.y / kTileSize);
  const int tx1 = std::min(canvas.tiles_x() - 1, (o.x + n.x - 1) / kTileSize);
  const int ty1 = std::min(canvas.tiles_y() - 1, (o.y + n.y - 1) / kTileSize);
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) tiles.push_back(snapshot_tile(canvas, ty * canvas.tiles_x() + tx));
  const auto restore = [&] {
    w->from_host(window);
    restore_particles(sim.particles(), particles);
    for (const TileSnapshot& t : tiles) restore_tile(canvas, t);
  };
  try {
    sim.settle();
    fn(canvas);
  } catch (...) {
    restore();
    throw;
  }
  restore();
}

TileStore settled_canvas_copy(Simulator& sim, const Device& device) {
  TileStore copy(device, sim.canvas().dims());
  with_settled_canvas(sim, [&](TileStore& c) {
    for (int id : c.allocated_tile_ids()) {
      TileData t = c.read_tile(id);
      if (tile_has_paint(t)) copy.write_tile(t);
    }
  });
  return copy;
}

void drop_particles(Simulator& sim) { sim.particles().clear(); }

void reload_window(Simulator& sim) {
  if (PaintWindow* w = sim.live_window()) sim.canvas().gather(*w);
}

int64_t particle_count(Simulator& sim) { return sim.particles().size(); }

}  // namespace wb::studio
