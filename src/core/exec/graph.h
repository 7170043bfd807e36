// LaunchGraph: a run of launches that repeats with the same arguments, recorded once as a CUDA
// graph and replayed whole, so the run costs one launch's latency instead of one a kernel.
// LaunchLoop: such a run repeated until a flag its last kernel writes says stop, a loop the
// device runs (a CUDA graph's conditional while node) without the host waiting on the flag.
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

/// Runs `body` (launches only, the same arguments for the same key) once and again while the flag
/// `*go` (device memory the body's last kernel writes: nonzero, once more) says so. The loop is the
/// device's: on CUDA the body is recorded into a conditional while node of a graph at a key's first
/// run and the host only launches the graph (no wait); on the CPU backend, whose device memory is
/// the host's, the flag is read where it lies. The body must not allocate (it is recorded as it
/// first runs: an allocation there fails the capture, loudly). On CUDA a run counts the body's
/// launches once: its further passes run on the device.
class LaunchLoop {
 public:
  LaunchLoop() = default;
  ~LaunchLoop() { reset(); }
  LaunchLoop(const LaunchLoop&) = delete;
  LaunchLoop& operator=(const LaunchLoop&) = delete;

  template <typename F>
  void run(const Device& d, uint64_t key, const uint32_t* go, F&& body) {
    if (!d.is_cuda()) {
      do body();
      while (*go != 0u);
      return;
    }
    if (!(exec_ && key == key_)) {
      const int64_t before = mem::launches();
      begin();
      try {
        body();
      } catch (...) {
        abandon();
        throw;
      }
      end(key, go, mem::launches() - before);
    }
    replay();
  }
  void reset() { drop(); }

 private:
  void drop();
  void begin();
  void end(uint64_t key, const uint32_t* go, int64_t launches);
  void abandon();
  void replay();
  void* exec_ = nullptr;   // cudaGraphExec_t
  void* graph_ = nullptr;  // cudaGraph_t whose conditional node's body is being recorded
  uint64_t handle_ = 0;    // cudaGraphConditionalHandle
  uint64_t key_ = 0;
  int64_t launches_ = 0;
};

}  // namespace wb
