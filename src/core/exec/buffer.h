// DeviceBuffer<T>: an RAII, move-only array that lives on one device. Transfers
// are always explicit (copy_to_host / copy_from_host): nothing moves behind the back.
#pragma once
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/exec/device.h"
#include "core/exec/error.h"
#include "core/exec/memory.h"

namespace wb {

template <typename T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(const Device& device, size_t n) : device_(device) { resize(n); }
  ~DeviceBuffer() { reset(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept { swap(o); }
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    if (this != &o) {
      reset();
      swap(o);
    }
    return *this;
  }

  void swap(DeviceBuffer& o) noexcept {
    std::swap(device_, o.device_);
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(capacity_, o.capacity_);
  }

  /// Binds an empty buffer to a device (no allocation).
  void set_device(const Device& device) {
    WB_REQUIRE(capacity_ == 0 || device == device_, "DeviceBuffer: cannot move a filled buffer to another device");
    device_ = device;
  }

  /// Resizes without keeping the contents; reallocates only when growing past capacity.
  void resize(size_t n) {
    if (n > capacity_) {
      reset();
      data_ = static_cast<T*>(mem::allocate(device_, n * sizeof(T)));
      capacity_ = n;
    }
    size_ = n;
  }
  /// Grows keeping the first size() elements, geometrically so that repeated growth is amortised.
  void grow_keep(size_t n) {
    if (n <= capacity_) {
      size_ = n;
      return;
    }
    size_t cap = capacity_ ? capacity_ : 16;
    while (cap < n) cap += cap / 2 + 1;
    T* fresh = static_cast<T*>(mem::allocate(device_, cap * sizeof(T)));
    if (size_) mem::copy_on_device(device_, fresh, data_, size_ * sizeof(T));
    if (data_) mem::release(device_, data_);
    data_ = fresh;
    capacity_ = cap;
    size_ = n;
  }
  void reset() noexcept {
    if (data_) mem::release(device_, data_);
    data_ = nullptr;
    size_ = capacity_ = 0;
  }

  void fill_zero() {
    if (size_) mem::fill_zero(device_, data_, size_ * sizeof(T));
  }
  void copy_from_host(const T* src, size_t n) {
    resize(n);
    if (n) mem::copy_from_host(device_, data_, src, n * sizeof(T));
  }
  void copy_from_host(const std::vector<T>& v) { copy_from_host(v.data(), v.size()); }
  void copy_to_host(T* dst, size_t n) const {
    WB_REQUIRE(n <= size_, "DeviceBuffer::copy_to_host: range past the end");
    if (n) mem::copy_to_host(device_, dst, data_, n * sizeof(T));
  }
  std::vector<T> to_host() const {
    std::vector<T> v(size_);
    copy_to_host(v.data(), size_);
    return v;
  }
  /// Copies count elements starting at offset into host memory.
  void copy_range_to_host(T* dst, size_t offset, size_t count) const {
    WB_REQUIRE(offset + count <= size_, "DeviceBuffer::copy_range_to_host: range past the end");
    if (count) mem::copy_to_host(device_, dst, data_ + offset, count * sizeof(T));
  }
  void copy_range_from_host(const T* src, size_t offset, size_t count) {
    WB_REQUIRE(offset + count <= size_, "DeviceBuffer::copy_range_from_host: range past the end");
    if (count) mem::copy_from_host(device_, data_ + offset, src, count * sizeof(T));
  }

  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  size_t bytes() const { return capacity_ * sizeof(T); }
  bool empty() const { return size_ == 0; }
  const Device& device() const { return device_; }

 private:
  Device device_{};
  T* data_ = nullptr;
  size_t size_ = 0;
  size_t capacity_ = 0;
};

}  // namespace wb
