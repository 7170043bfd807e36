// `wetbrush params`: the parameter table (ids for --set, defaults, ranges, units, paper refs).
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "core/params/param_table.h"

namespace wb::cli {

void register_params(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("params", "List every simulation and rendering parameter");
  auto json = std::make_shared<bool>(false);
  sub->add_flag("--json", *json, "Print the defaults as a parameter file (JSON)");
  set_action(sub, [json]() {
    if (*json) {
      std::printf("%s\n", params_to_json(SimParams{}).dump(2).c_str());
      return 0;
    }
    std::printf("%-34s %12s %12s %12s  %-10s %-8s %s\n", "id", "default", "min", "max", "unit", "paper", "what");
    for (const ParamInfo& p : param_table())
      std::printf("%-34s %12g %12g %12g  %-10s %-8s %s\n", p.id.c_str(), p.default_value(), p.min, p.max,
                  p.unit.c_str(), p.paper.c_str(), p.tooltip.c_str());
    return 0;
  });
}

}  // namespace wb::cli
