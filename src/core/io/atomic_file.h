// Atomic file writes (docs/RELIABILITY.md "Saves"): the bytes go to a temporary file beside the
// target (`.NAME.tmp-PID-XXXXXX`), which is fsynced and renamed over it, and the directory is
// fsynced. A reader sees the old file or the new one, never a part; a failure leaves the old
// file and no temporary behind, and the next write removes those of writers that were killed.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace wb {

/// Writes `size` bytes at `data` to `path` atomically. `fault_hook` (tests) is called with
/// "partial-write" half-way through the bytes and "before-rename".
void write_file_atomic(const std::string& path, const void* data, size_t size,
                       const std::function<void(const std::string&)>& fault_hook = {});
void write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes,
                       const std::function<void(const std::string&)>& fault_hook = {});
void write_file_atomic(const std::string& path, const std::string& text);

}  // namespace wb
