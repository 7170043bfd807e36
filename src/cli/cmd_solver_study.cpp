// `wetbrush solver-study`: the convergence of the pressure solvers on a real window's
// system (paper §4.2, Figure 6): error against a CG solution and residual after each sweep.
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "core/grid/solver_study.h"

namespace wb::cli {

void register_solver_study(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "solver-study", "Error and residual per sweep of Jacobi, weighted Jacobi, Chebyshev and the fixed-point "
                      "method (Algorithm 1, alpha = 0, 0.5, 1) on a real window's pressure system (paper Figure 6)");
  struct Opts {
    int size = 64;
    int sweeps = 40;
    unsigned seed = 1;
    bool json = false;
    std::string scene = "window";
    std::string device;
  };
  auto o = std::make_shared<Opts>();
  sub->add_option("--size", o->size, "Window of size x size x max(size/4, 8) cells")->capture_default_str()->check(CLI::Range(16, 512));
  sub->add_option("--sweeps", o->sweeps, "Report sweeps 0..K")->capture_default_str()->check(CLI::Range(0, 10000));
  sub->add_option("--seed", o->seed, "Seed of the scene's paint and bristle noise")->capture_default_str();
  sub->add_option("--scene", o->scene,
                  "window: paint layer + pressed brush (size x size x size/4); cube: size^3 liquid, random velocity")
      ->capture_default_str()
      ->check(CLI::IsMember({"window", "cube"}));
  sub->add_flag("--json", o->json, "Print JSON instead of a table");
  add_device_option(sub, o->device);
  set_action(sub, [o]() {
    const Device d = resolve_device(o->device);
    const SolverStudyResult r = run_solver_study(
        d, o->size, o->sweeps, o->seed, o->scene == "cube" ? StudySceneKind::kCube : StudySceneKind::kBrushWindow);
    const std::string out = o->json ? solver_study_json(r) : solver_study_text(r);
    std::fwrite(out.data(), 1, out.size(), stdout);
    if (o->json) std::printf("\n");
    return 0;
  });
}

}  // namespace wb::cli
