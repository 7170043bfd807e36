// Fuzz harness: brush presets (the studio's preset files, the "brush" object of stroke files):
// JSON text as the studio reads it, then brush_from_json and a write-read round trip.
#include <nlohmann/json.hpp>

#include "core/io/brush_json.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, false);
  if (j.is_discarded()) return 0;  // not JSON: the caller reports nlohmann's parse error
  wb::fuzz::expect_clean([&] {
    std::vector<std::string> warnings;
    const wb::BrushSpec b = wb::brush_from_json(j, "fuzz-preset.json", "", &warnings);
    // What was accepted writes and reads back to the same brush.
    if (!(wb::brush_from_json(wb::brush_to_json(b), "round trip", "") == b)) __builtin_trap();
  });
  return 0;
}
