// Raw device memory: the one place that allocates, frees and copies on either backend.
#pragma once
#include <cstddef>

#include "core/exec/device.h"

namespace wb::mem {

void* allocate(const Device& device, size_t bytes);
void release(const Device& device, void* ptr) noexcept;
void copy_to_host(const Device& device, void* host_dst, const void* dev_src, size_t bytes);
void copy_from_host(const Device& device, void* dev_dst, const void* host_src, size_t bytes);
void copy_on_device(const Device& device, void* dst, const void* src, size_t bytes);
void fill_zero(const Device& device, void* ptr, size_t bytes);

}  // namespace wb::mem
