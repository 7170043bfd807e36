// TouchList: the elements of a field that a scatter pass reached, each listed once (a flag per
// element and an atomic count). The passes after the scatter visit the list, not the field, and
// the field goes back to zero through it, so their work follows what was reached, not the size
// of the field: Eq. 16's deposit (DepositScratch) and the particles' raster (ParticleRasterView).
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/exec/atomics.h"
#include "core/exec/buffer.h"
#include "core/exec/hd.h"

namespace wb {

/// By value in a kernel. Null: nothing is listed (a field its caller zeroes whole).
struct TouchList {
  int32_t* listed = nullptr;  ///< per element: 1 while it is in `items`
  uint32_t* items = nullptr;  ///< the elements listed, in the order reached
  int64_t* count = nullptr;   ///< their number (device memory)
  WB_HD bool on() const { return listed != nullptr; }
  /// Lists element i unless it is listed already (most touches find it listed: a load, no
  /// read-modify-write).
  WB_HD void touch(int64_t i) const {
    if (atomic_load(&listed[i]) == 0 && atomic_or(&listed[i], int32_t(1)) == 0)
      items[atomic_add(count, int64_t(1))] = uint32_t(i);
  }
};

/// The list's buffers for a field of n elements (fewer than 2^32). The flags are zeroed when the
/// size changes; after that whoever empties the list clears each listed element's flag (and its
/// field) and then the count (clear_count), so that no pass over the whole field is needed.
class TouchListBuffers {
 public:
  void set_device(const Device& d) {
    listed_.set_device(d);
    items_.set_device(d);
    count_ = DeviceBuffer<int64_t>(d, 1);
    count_.fill_zero();
  }
  /// Sized for n elements; flags and count zero where the size changed.
  void ensure(int64_t n) {
    if (listed_.size() == size_t(n)) return;
    listed_.resize(size_t(n));
    listed_.fill_zero();
    items_.resize(size_t(n));
    count_.fill_zero();
  }
  void clear_count() { count_.fill_zero(); }
  int64_t capacity() const { return int64_t(listed_.size()); }
  TouchList view() { return TouchList{listed_.data(), items_.data(), count_.data()}; }

 private:
  DeviceBuffer<int32_t> listed_;
  DeviceBuffer<uint32_t> items_;
  DeviceBuffer<int64_t> count_;
};

}  // namespace wb
