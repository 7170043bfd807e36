// Subcommand registry of the CLI. Each cmd_*.cpp defines one register_* function that
// adds its subcommand with --help and sets a callback; main() runs the chosen one.
#pragma once
#include <CLI/CLI.hpp>

#include <functional>
#include <string>

#include "core/exec/device.h"

namespace wb::cli {

/// Adds the common --device option to a subcommand.
void add_device_option(CLI::App* sub, std::string& device_text);
/// Adds --progress-every: seconds between the progress lines a long command writes to a log.
void add_progress_option(CLI::App* sub, double& seconds);
/// Parses the --device text ("auto" by default).
Device resolve_device(const std::string& device_text);

/// Sets what the subcommand does; the function returns the process exit code.
void set_action(CLI::App* sub, std::function<int()> action);

void register_devices(CLI::App& app);
void register_render(CLI::App& app);
void register_export(CLI::App& app);
void register_replay(CLI::App& app);
void register_params(CLI::App& app);
void register_solver_study(CLI::App& app);
void register_all(CLI::App& app);
int run_selected(CLI::App& app);

}  // namespace wb::cli
