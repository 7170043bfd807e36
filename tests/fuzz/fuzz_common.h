// Shared by the libFuzzer harnesses: a reader may throw wb::Error (a clear message for a bad
// file); anything else escaping it (another exception type, a crash, a sanitizer report, a
// leak) is a finding. tests/fuzz/README.md: building and running them.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/exec/error.h"

namespace wb::fuzz {

inline std::string_view text_of(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Runs `read`; a wb::Error is the expected outcome for most inputs.
template <class F>
void expect_clean(F&& read) {
  try {
    read();
  } catch (const wb::Error&) {
  }
}

}  // namespace wb::fuzz
