#include "cli/commands.h"

#include <map>

namespace wb::cli {
namespace {
std::map<CLI::App*, std::function<int()>>& actions() {
  static std::map<CLI::App*, std::function<int()>> a;
  return a;
}
}  // namespace

void add_device_option(CLI::App* sub, std::string& device_text) {
  device_text = "auto";
  sub->add_option("--device", device_text, "Backend: auto (CUDA when a GPU is present), cpu, cuda or cuda:N")
      ->capture_default_str();
}

void add_progress_option(CLI::App* sub, double& seconds) {
  sub->add_option("--progress-every", seconds,
                  "Seconds between the progress lines written when standard error is not a terminal (a log)")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
}

Device resolve_device(const std::string& device_text) {
  Device d = Device::parse(device_text);
  d.activate();
  return d;
}

void set_action(CLI::App* sub, std::function<int()> action) { actions()[sub] = std::move(action); }

void register_all(CLI::App& app) {
  register_devices(app);
  register_render(app);
  register_export(app);
  register_replay(app);
  register_params(app);
  register_solver_study(app);
}

int run_selected(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands()) {
    auto it = actions().find(sub);
    if (it != actions().end()) return it->second();
  }
  return 2;
}

}  // namespace wb::cli
