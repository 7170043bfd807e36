// SimParams: every tunable of the simulator and renderer in one POD grouped by stage
// (p.grid.jacobi_L, p.particles.beta_L, ...). Kernels receive their group by value.
// The brush's own shape and material (incl. beta_B) live in BrushSpec, a preset.
#pragma once
#include "core/brush/brush.h"
#include "core/grid/grid_params.h"
#include "core/particles/particle_params.h"
#include "core/render/render_params.h"
#include "core/transfer/transfer_params.h"

namespace wb {

struct SimParams {
  BrushSolverParams brush_solver{};
  GridParams grid{};
  ParticleParams particles{};
  RenderParams render{};
  TransferParams transfer{};
  /// Drag of the paint flow on the bristles (Eq. 2's a_i, kept grid velocity of §4.3):
  /// velocity relaxes towards the flow at this rate times the paint density, 1/s.
  float bristle_drag = 20.f;
};

}  // namespace wb
