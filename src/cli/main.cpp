// wetbrush: the headless command-line front end (no Qt). Each subcommand lives in
// its own cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "cli/commands.h"
#include "core/exec/error.h"
#include "core/exec/memory.h"

int main(int argc, char** argv) {
  CLI::App app{"wetbrush: bristle-level 3D oil-paint simulator (headless tools)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "wetbrush " WB_VERSION);
  // Errors say what is wrong in the user's terms; the source location that raised one is for a
  // bug report, on request. Options the subcommands do not know fall through to here, so
  // --verbose goes anywhere on the line.
  bool verbose = false;
  app.add_flag("--verbose", verbose, "Errors also name the source location that raised them (for a bug report)")
      ->envname("WB_VERBOSE");
  std::string memory_limit;
  app.add_option("--memory-limit", memory_limit,
                 "Most memory a run may hold, host and GPU each (e.g. 4G, 512M); without it, what the machine has "
                 "available. A run larger than this is refused before it allocates")
      ->envname("WB_MEMORY_LIMIT");
  app.fallthrough();
  wb::cli::register_all(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    wb::mem::set_budget_from(memory_limit);
    return wb::cli::run_selected(app);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wetbrush: error: %s\n", verbose ? e.what() : wb::user_message(e).c_str());
    return 1;
  }
}
