// wetbrush: the headless command-line front end (no Qt). Each subcommand lives in
// its own cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "cli/commands.h"
#include "core/exec/error.h"

int main(int argc, char** argv) {
  CLI::App app{"wetbrush: bristle-level 3D oil-paint simulator (headless tools)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "wetbrush 0.1.0");
  wb::cli::register_all(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return wb::cli::run_selected(app);
  } catch (const wb::Error& e) {
    std::fprintf(stderr, "wetbrush: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wetbrush: error: %s\n", e.what());
    return 1;
  }
}
