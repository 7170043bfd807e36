// LaunchGraph: a run of launches that repeats with the same arguments, recorded once as a CUDA
// graph and replayed whole, so the run costs one launch's latency instead of one a kernel.
#pragma once
#include <bit>
#include <cstdint>
#include <initializer_list>

#include "core/exec/device.h"
#include "core/exec/memory.h"

namespace wb {

/// A key for LaunchGraph::run from what its launches depend on: the buffers' addresses and the
/// sizes they were launched over. A different key records the launches again.
inline uint64_t launch_key(std::initializer_list<uint64_t> parts) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a over the parts' bytes
  for (uint64_t p : parts)
    for (int b = 0; b < 8; ++b) h = (h ^ ((p >> (8 * b)) & 0xffu)) * 1099511628211ull;
  return h;
}
inline uint64_t launch_key_of(const void* p) { return uint64_t(reinterpret_cast<uintptr_t>(p)); }
/// A float argument's bits, for a key.
inline uint64_t launch_key_of(float f) { return std::bit_cast<uint32_t>(f); }

class LaunchGraph {
 public:
  LaunchGraph() = default;
  ~LaunchGraph() { reset(); }
  LaunchGraph(const LaunchGraph&) = delete;
  LaunchGraph& operator=(const LaunchGraph&) = delete;

  /// Runs `launches`, a function that only queues device work on the simulator's stream (no
  /// host read; the same arguments for the same key). On CUDA a key's first run is made
  /// directly (a workspace it grows grows then, outside a recording), its second is recorded,
  /// and the recording is replayed from then on, until the key changes; on the CPU, called.
  template <typename F>
  void run(const Device& d, uint64_t key, F&& launches) {
    if (!d.is_cuda()) {
      launches();
      return;
    }
    if (!(exec_ && key == key_) && key != seen_) {
      seen_ = key;
      launches();
      return;
    }
    const bool recorded = !(exec_ && key == key_);
    if (recorded) {
      const int64_t before = mem::launches();
      begin();
      try {
        launches();
      } catch (...) {
        abandon();
        throw;
      }
      end(key, mem::launches() - before);
    }
    replay(!recorded);
  }
  /// Drops the recording and the key seen (the next run starts over).
  void reset();

 private:
  void drop();  // the recording alone
  void begin();
  void end(uint64_t key, int64_t launches);
  void abandon();
  void replay(bool count);
  void* exec_ = nullptr;  // cudaGraphExec_t
  uint64_t key_ = 0;
  uint64_t seen_ = 0;     // the key of the last direct run
  int64_t launches_ = 0;  // the kernels recorded: counted as launches on every replay
};

}  // namespace wb
