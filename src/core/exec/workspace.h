// Scratch memory for the algorithms (radix-sort ping-pong buffers, CUB temp storage) and a
// stage's scratch between two of its launches (the samples' motion of the adhesion step).
// It grows geometrically and is kept, so the per-step path never allocates once warm.
#pragma once
#include <cstddef>

#include "core/exec/buffer.h"

namespace wb {

class Workspace {
 public:
  Workspace() = default;
  explicit Workspace(const Device& device) { buf_.set_device(device); }
  const Device& device() const { return buf_.device(); }
  /// Returns at least `bytes` of scratch, 256-byte aligned; invalidates earlier pointers.
  void* get(size_t bytes) {
    if (bytes > buf_.size()) {
      buf_.reset();
      buf_.resize(bytes + bytes / 2);
    }
    return buf_.data();
  }
  size_t bytes() const { return buf_.bytes(); }
  const void* data() const { return buf_.data(); }

 private:
  DeviceBuffer<unsigned char> buf_;
};

}  // namespace wb
