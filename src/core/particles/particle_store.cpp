// Particle storage: growth, batch append, flag-and-compact removal (paper §4.3, §5).
#include "core/particles/particle_store.h"

#include <algorithm>
#include <string>

#include "core/exec/algorithms.h"
#include "core/exec/error.h"
#include "core/particles/particles.h"

namespace wb {

void ParticleHost::resize(size_t n) {
#define WB_X(type, name, doc) name.resize(n);
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
}

ParticleStore::ParticleStore(const Device& device, int64_t limit) : device_(device) {
#define WB_X(type, name, doc) name.set_device(device);
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
#define WB_X(type, name, doc) spare_##name##_.set_device(device);
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  scan_.set_device(device);
  order_.set_device(device);
  set_limit(limit);
}

void ParticleStore::set_limit(int64_t limit) {
  WB_REQUIRE(limit > 0 && limit < (int64_t(1) << 31),
             "ParticleStore: the particle limit must lie in [1, 2^31), got " + std::to_string(limit));
  WB_REQUIRE(limit >= count_, "ParticleStore: limit " + std::to_string(limit) + " is below the " +
                                  std::to_string(count_) + " particles held");
  limit_ = limit;
}

void ParticleStore::reserve(int64_t n) {
  WB_REQUIRE(n >= 0, "ParticleStore::reserve: negative count");
  WB_REQUIRE(n <= limit_, "ParticleStore: " + std::to_string(n) + " particles exceed the limit of " +
                              std::to_string(limit_));
  if (n <= capacity_) return;
  // Doubling, so that a growing particle count costs O(log n) reallocations in all.
  int64_t cap = std::max<int64_t>(capacity_, 1024);
  while (cap < n) cap *= 2;
  cap = std::min(cap, limit_);
#define WB_X(type, name, doc) name.grow_keep(size_t(cap));
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
  capacity_ = cap;
}

int64_t ParticleStore::append_uninitialised(int64_t n) {
  WB_REQUIRE(n >= 0, "ParticleStore::append: negative count");
  const int64_t first = count_;
  reserve(count_ + n);
  count_ += n;
  particles_init_scratch(device_, view(), first, n);
  return first;
}

int64_t ParticleStore::append(const ParticleHost& b) {
  const size_t n = b.size();
#define WB_X(type, name, doc)                                                                                    \
  WB_REQUIRE(b.name.size() == n, "ParticleStore::append: field '" #name "' has " + std::to_string(b.name.size()) + \
                                     " entries, position has " + std::to_string(n));
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  const int64_t first = append_uninitialised(int64_t(n));
#define WB_X(type, name, doc) name.copy_range_from_host(b.name.data(), size_t(first), n);
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  return first;
}

int64_t ParticleStore::compact(Workspace& ws) {
  const int64_t n = count_;
  if (n == 0) return 0;
  if (scan_.size() < size_t(n)) scan_.grow_keep(size_t(n));
  particles_keep_flags(device_, dead.data(), m.data(), scan_.data(), n);
  const int64_t kept = int64_t(exclusive_scan(device_, scan_.data(), scan_.data(), n, ws));
  remove_dead(scan_.data(), kept);
  return n - kept;
}

void ParticleStore::remove_dead(const uint32_t* pos, int64_t kept) {
  const int64_t n = count_;
  WB_REQUIRE(kept >= 0 && kept <= n, "ParticleStore::remove_dead: " + std::to_string(kept) + " kept of " +
                                         std::to_string(n));
  if (kept == n) return;
  // The state alone, in one pass into the spare set: `nearest` and `d_B` are written again by
  // the next query before anything reads them, and the dead flags are cleared.
  particles_compact_state(device_, view(), spare_view(), pos, n);
  swap_spare();
  dead.fill_zero();
  count_ = kept;
}

ParticleStateView ParticleStore::spare_view() {
  // The spare set as large as the state arrays (their contents are not kept: a move rewrites
  // every live entry), so that the two sets can swap.
  ParticleStateView out;
#define WB_X(type, name, doc)                                     \
  if (spare_##name##_.size() != name.size()) spare_##name##_.resize(name.size()); \
  out.name = spare_##name##_.data();
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  return out;
}

void ParticleStore::swap_spare() {
#define WB_X(type, name, doc) name.swap(spare_##name##_);
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
}

void ParticleStore::sort_by_cell(Int3 origin, Int3 dims, Workspace& ws) {
  const int64_t n = count_;
  if (n <= 1) return;
  if (scan_.size() < size_t(n)) scan_.grow_keep(size_t(n));
  if (order_.size() < size_t(n)) order_.grow_keep(size_t(n));
  particles_cell_keys(device_, view(), origin, dims, scan_.data(), order_.data());
  const int64_t cells = int64_t(8) * dims.x * dims.y * dims.z;  // half cells: the key of a particle outside
  int bits = 1;
  while ((int64_t(1) << bits) <= cells) ++bits;
  sort_by_key(device_, scan_.data(), order_.data(), n, bits, ws);
  // The state only, in one pass into the spare set: the sort comes before the step's queries,
  // which write `nearest` and `d_B` again, and after the last compaction, which left every
  // `dead` flag clear.
  particles_gather_state(device_, view(), spare_view(), order_.data(), n);
  swap_spare();
}

ParticleView ParticleStore::view() {
  ParticleView out;
#define WB_X(type, name, doc) out.name = name.data();
  WB_PARTICLE_FIELDS(WB_X)
#undef WB_X
  out.count = count_;
  return out;
}

ParticleHost ParticleStore::to_host() const {
  ParticleHost h;
  h.resize(size_t(count_));
#define WB_X(type, name, doc) name.copy_range_to_host(h.name.data(), 0, size_t(count_));
  WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  return h;
}

double ParticleStore::total_mass(Workspace& ws) const { return reduce_sum(device_, m.data(), count_, ws); }

}  // namespace wb
