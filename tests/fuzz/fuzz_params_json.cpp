// Fuzz harness: parameter files (`wetbrush replay --params file.json`): JSON text as the CLI
// reads it, then params_from_json over the defaults.
#include <nlohmann/json.hpp>

#include "core/params/param_table.h"
#include "core/params/sim_params.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, false);
  if (j.is_discarded()) return 0;  // not JSON: the caller reports nlohmann's parse error
  wb::fuzz::expect_clean([&] {
    wb::SimParams p;
    std::vector<std::string> warnings;
    wb::params_from_json(p, j, warnings);
  });
  return 0;
}
