// Particle storage (paper §4.3, §5): SoA device buffers generated from the field list.
// Capacity grows geometrically up to a limit (default 2M, §7); particles are added in
// batches and removed by flag plus one stream compaction, so a warm step never allocates.
#pragma once
#include <cstdint>
#include <vector>

#include "core/exec/buffer.h"
#include "core/exec/device.h"
#include "core/exec/workspace.h"
#include "core/canvas/window.h"
#include "core/particles/particle_fields.h"

namespace wb {

/// Host copy of the particle state (one vector per state field, all the same length).
struct ParticleHost {
#define WB_X(type, name, doc) std::vector<type> name;
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  size_t size() const { return x.size(); }
  void resize(size_t n);
};

class ParticleStore {
 public:
  ParticleStore() = default;
  explicit ParticleStore(const Device& device, int64_t limit = 2000000);

  int64_t size() const { return count_; }
  int64_t capacity() const { return capacity_; }
  int64_t limit() const { return limit_; }
  const Device& device() const { return device_; }
  void set_limit(int64_t limit);

  /// Makes room for n particles in total (keeps the live ones); throws past the limit.
  void reserve(int64_t n);
  /// Appends n particles whose fields are left for the caller's kernels to fill (emission);
  /// returns the index of the first. Scratch fields of the new ones: nearest -1, dead 0.
  int64_t append_uninitialised(int64_t n);
  /// Appends particles from host arrays (all state fields the same length); returns the first index.
  int64_t append(const ParticleHost& batch);
  /// Removes every particle whose `dead` flag is set, keeping the order of the survivors
  /// (exclusive scan of the keep flags, then a scatter of every field). Returns how many went.
  int64_t compact(Workspace& ws);
  /// The scatter of compact() for a scan made elsewhere: pos = exclusive scan of the keep flags
  /// (particles_keep_flags) of the size() particles, kept = their total.
  void remove_dead(const uint32_t* pos, int64_t kept);
  /// Puts the particles in the order of their half cells (a cell halved along each axis: every
  /// raster stencil's corner is constant over one) in the window of `dims` cells at canvas cell
  /// `origin` (x fastest; those outside it last), each half cell's in their order before (a
  /// stable radix sort, then a gather of every state field): neighbours in space are neighbours
  /// in memory. The per-step scratch is left as it is: call it where no `dead` flag is set and
  /// before the queries that write `nearest` and `d_B`.
  void sort_by_cell(Int3 origin, Int3 dims, Workspace& ws);
  void clear() { count_ = 0; }

  ParticleView view();
  ParticleHost to_host() const;
  /// Sum of the particle masses (kg), in double.
  double total_mass(Workspace& ws) const;

#define WB_X(type, name, doc) DeviceBuffer<type> name;
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X

 private:
  Device device_;
  int64_t count_ = 0;
  int64_t capacity_ = 0;
  int64_t limit_ = 2000000;
  DeviceBuffer<uint32_t> scan_;     ///< keep flags, then their exclusive scan; the sort's keys
  DeviceBuffer<uint32_t> order_;    ///< the sort's old index of each new place
  /// A second set of the state arrays, as large as the store: a compaction or a sort writes
  /// every particle's state there in one pass, and the two sets swap.
#define WB_X(type, name, doc) DeviceBuffer<type> spare_##name##_;
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  ParticleStateView spare_view();
  void swap_spare();
};

}  // namespace wb
