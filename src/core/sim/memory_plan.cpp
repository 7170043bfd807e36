#include "core/sim/memory_plan.h"

#include <algorithm>

#include "core/canvas/tile_store.h"
#include "core/exec/error.h"
#include "core/exec/memory.h"
#include "core/particles/particle_fields.h"
#include "core/render/raycast_kernels.h"
#include "core/sim/simulator.h"

namespace wb {
namespace {
// Measured with the CPU backend's ledger (tests/sim/memory_budget_test.cpp checks the estimate
// against what a run holds): every buffer the grid, the paint window, the rasters and the
// per-step scratch size by the window's cells, after the first steps allocated the lazy ones
// (the viscous solve's vectors, sized to every face of the window, about 200 of them).
constexpr int64_t kWindowBytesPerCell = 592;
// Bristle vertices and samples, their loads and the brush's scratch, per sample.
constexpr int64_t kBrushBytesPerSample = 300;
// The profiler, the workspaces and the small device buffers.
constexpr int64_t kFixedBytes = int64_t(4) << 20;

// A canvas cell of a tile: density (float), four pigment and oil channels and dryness (16-bit).
constexpr int64_t kTileBytesPerCell = sizeof(float) + 5 * sizeof(uint16_t);

// A pixel of a whole-canvas render (Renderer): its top (16-bit) and film column, the float
// material maps' four channels (the larger output), and the host's image and its copy (RGBA8).
constexpr int64_t kPictureBytesPerPixel = sizeof(uint16_t) + sizeof(FilmColumn) + 4 * sizeof(float) + 2 * 4;

#define WB_X(type, name, doc) +int64_t(sizeof(type))
constexpr int64_t kParticleFieldBytes = 0 WB_PARTICLE_FIELDS(WB_X);
constexpr int64_t kParticleStateBytes = 0 WB_PARTICLE_STATE_FIELDS(WB_X);
#undef WB_X
// The compaction's scan and the sort's order (4 + 4), the sort's keys and the transfer's room
// counts and offsets (4 + 4 + 4 + 4).
constexpr int64_t kParticleScratchBytes = 24;
}  // namespace

MemoryPlan plan_memory(const SimConfig& c) {
  MemoryPlan p;
  p.window_cells = int64_t(c.window.x) * c.window.y * c.window.z;
  p.window = p.window_cells * kWindowBytesPerCell;
  p.brush = int64_t(c.brush.bristles) * c.brush.samples_per_bristle * kBrushBytesPerSample;
  // The tiles under the window, one more along each side as it moves, a column of the canvas's
  // depth each; the pool doubles when it grows.
  const int64_t tiles = int64_t(c.window.x / kTileSize + 2) * (c.window.y / kTileSize + 2);
  p.canvas = 2 * tiles * kTileSize * kTileSize * c.canvas.depth * kTileBytesPerCell;
  p.picture = int64_t(c.canvas.width) * c.canvas.height * kPictureBytesPerPixel;
  p.fixed = kFixedBytes;
  p.per_particle = (kParticleFieldBytes + kParticleStateBytes + kParticleScratchBytes) * 3 / 2;
  return p;
}

int64_t ground_bytes(const CanvasDims& d) {
  const int64_t tiles = int64_t((d.width + kTileSize - 1) / kTileSize) * ((d.height + kTileSize - 1) / kTileSize);
  return tiles * kTileSize * kTileSize * d.depth * kTileBytesPerCell;
}

int64_t check_memory(const MemoryPlan& plan, const SimConfig& c, int64_t particle_limit) {
  const bool cuda = !c.device.is_cpu();
  const size_t room = mem::room(c.device);
  const size_t budget = mem::budget(cuda);
  const char* what = cuda ? "GPU" : "host";
  if (size_t(plan.base()) > room) {
    const std::string of =
        budget > 0 && room < mem::available(c.device)
            ? "the memory budget leaves " + mem::format_bytes(double(room)) + " (--memory-limit " +
                  mem::format_bytes(double(budget)) + ")"
            : "the machine has " + mem::format_bytes(double(room)) + " of " + what + " memory available";
    WB_THROW("the simulation window of " + std::to_string(c.window.x) + " x " + std::to_string(c.window.y) + " x " +
             std::to_string(c.window.z) + " cells needs about " + mem::format_bytes(double(plan.base())) + " of " +
             what + " memory (" + mem::format_bytes(double(plan.window)) + " for its " +
             std::to_string(plan.window_cells) + " cells), and " + of +
             ": choose a smaller window (simulation.window in the stroke file, or --window)");
  }
  const int64_t left = int64_t(room) - plan.base();
  return std::max<int64_t>(1, std::min<int64_t>(particle_limit, left / plan.per_particle));
}

}  // namespace wb
