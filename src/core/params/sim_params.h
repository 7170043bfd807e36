// SimParams: every tunable of the simulator and renderer in one POD grouped by stage
// (p.grid.jacobi_L, p.particles.beta_L, ...). Kernels receive their group by value.
// The brush's own shape and material (incl. beta_B) live in BrushSpec, a preset.
#pragma once
#include "core/brush/brush.h"
#include "core/grid/grid_params.h"
#include "core/particles/particle_params.h"
#include "core/render/render_params.h"

namespace wb {

struct SimParams {
  BrushSolverParams brush_solver{};
  GridParams grid{};
  ParticleParams particles{};
  RenderParams render{};
};

}  // namespace wb
