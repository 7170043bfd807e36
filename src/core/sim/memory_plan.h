// The memory a simulation will hold, estimated from its configuration before the first
// allocation (docs/RELIABILITY.md "Memory budgets"), and the check of that estimate against the
// room the machine and the budget (mem::set_budget, --memory-limit) leave: a run too large for
// the machine is refused at once with the input that asks for the memory, not after minutes of
// allocations.
#pragma once
#include <cstdint>
#include <string>

#include "core/exec/device.h"

namespace wb {

struct SimConfig;
struct CanvasDims;

struct MemoryPlan {
  int64_t window_cells = 0;
  int64_t window = 0;  ///< the grid's, the paint window's and the rasters' fields, bytes
  int64_t brush = 0;   ///< bristles, samples and their loads, bytes
  int64_t canvas = 0;  ///< canvas tiles the window can hold at once, with the pool's doubling, bytes
  int64_t picture = 0; ///< a render of the whole canvas (top map, film, pixels, the host's image), bytes
  int64_t fixed = 0;   ///< what does not grow with the input, bytes
  /// Each particle of the store's capacity, its second state set and scratch (bytes); the store
  /// grows by doubling, so its peak is 1.5 of the capacity while one growth copies.
  int64_t per_particle = 0;
  int64_t base() const { return window + brush + canvas + picture + fixed; }
};

/// The estimate for `config` (its window, brush and canvas depth).
MemoryPlan plan_memory(const SimConfig& config);

/// Bytes a canvas ground takes: every tile of the canvas is allocated (TileStore::lay_weave).
int64_t ground_bytes(const CanvasDims& canvas);

/// Throws wb::Error when `plan` does not fit the room on `device` (mem::room): the message
/// names the window, the bytes it needs and the budget. Returns the particle limit the room
/// leaves after the plan's base, at most `particle_limit`.
int64_t check_memory(const MemoryPlan& plan, const SimConfig& config, int64_t particle_limit);

}  // namespace wb
