// Raw device memory: the one place that allocates, frees and copies on either backend.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/exec/device.h"

namespace wb::mem {

void* allocate(const Device& device, size_t bytes);
void release(const Device& device, void* ptr) noexcept;
void copy_to_host(const Device& device, void* host_dst, const void* dev_src, size_t bytes);
void copy_from_host(const Device& device, void* dev_dst, const void* host_src, size_t bytes);
/// dst and src do not overlap (cudaMemcpy's rule).
void copy_on_device(const Device& device, void* dst, const void* src, size_t bytes);
void fill_zero(const Device& device, void* ptr, size_t bytes);

/// Bytes held by live allocations of this module, per backend (CPU or all CUDA devices), and
/// the most held at once since the last reset_peak: the memory figure of `wetbrush bench`.
struct Usage {
  size_t in_use = 0;
  size_t peak = 0;
};
Usage usage(bool cuda);
void reset_peak();

/// The memory budget of this process, per backend (CPU or all CUDA devices), in bytes: an
/// allocation that would hold more fails at once with a message naming the budget, before the
/// system is asked (docs/RELIABILITY.md "Memory budgets"). 0: none but the machine's.
void set_budget(bool cuda, size_t bytes);
size_t budget(bool cuda);
/// Memory the machine can still give this process: the host's available memory (MemAvailable,
/// under a cgroup's limit where one is set), or the free memory of `device`'s GPU.
size_t available(const Device& device);
/// What a new allocation on `device` may take: the machine's available memory, and no more than
/// what the budget leaves.
size_t room(const Device& device);
/// "1.50 GiB", "12.0 MiB", "512 bytes": sizes in messages.
std::string format_bytes(double bytes);
/// A size a user gives (--memory-limit): bytes, or a number with K, M, G or T (powers of 1024;
/// "KiB", "MB" and the like read the same), e.g. "512M", "1.5G". Throws wb::Error on anything else.
size_t parse_size(const std::string& text);
/// Sets the host and GPU budgets from a user's size (parse_size); an empty text sets none.
void set_budget_from(const std::string& text);

/// Reads by the host of results the device computed (a copy to the host, a reduction's value, a
/// scan's total) made by the calling thread so far. On CUDA each one drains the stream and
/// waits; on the CPU backend the same call sites are counted, so a test there measures what
/// the GPU would wait for.
int64_t host_reads();
/// Counts one such read (copy_to_host and every primitive of algorithms.h that returns a value).
void count_host_read();

/// Device launches (kernels, device copies and fills, one per primitive of algorithms.h) the
/// calling thread has issued so far. On CUDA each costs a few microseconds of launch latency
/// whatever its size; the CPU backend counts the same call sites, so a bench there shows how
/// many a step makes on the GPU.
int64_t launches();
void count_launch();

}  // namespace wb::mem
