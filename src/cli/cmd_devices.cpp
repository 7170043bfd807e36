// `wetbrush devices`: the backends compiled in and the devices found at run time.
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "core/exec/selftest.h"

namespace wb::cli {

void register_devices(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("devices", "List the backends compiled in and the devices found");
  auto check = std::make_shared<bool>(false);
  auto only = std::make_shared<std::string>();
  sub->add_flag("--check", *check, "Run a self-test kernel (atomics, parallel_for) on each device");
  sub->add_option("--device", *only, "Show (and check) only this device: cpu, cuda, cuda:N or auto");
  set_action(sub, [check, only]() {
    const bool filtered = !only->empty();
    const Device wanted = filtered ? resolve_device(*only) : Device();
    std::printf("backends compiled in: cpu%s\n", cuda_compiled() ? ", cuda" : "");
    std::printf("auto selects: %s\n", Device::auto_select().to_string().c_str());
    int failures = 0;
    for (const DeviceInfo& info : list_devices()) {
      if (filtered && !(info.device == wanted)) continue;
      std::printf("%-8s %s", info.device.to_string().c_str(), info.name.c_str());
      if (info.memory_bytes) std::printf(", %.1f GiB", double(info.memory_bytes) / (1 << 30));
      if (!info.detail.empty()) std::printf(" (%s)", info.detail.c_str());
      if (*check) {
        const std::string err = selftest_run(info.device);
        std::printf("  self-test: %s", err.empty() ? "ok" : err.c_str());
        failures += err.empty() ? 0 : 1;
      }
      std::printf("\n");
    }
    if (cuda_compiled() && cuda_device_count() == 0) std::printf("no CUDA device found at run time\n");
    return failures ? 1 : 0;
  });
}

}  // namespace wb::cli
