#include "core/params/param_table.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <type_traits>

#include "core/exec/error.h"

namespace wb {
namespace {

template <typename T>
constexpr ParamKind kind_of() {
  if constexpr (std::is_same_v<T, bool>) return ParamKind::Bool;
  else if constexpr (std::is_integral_v<T> || std::is_enum_v<T>) return ParamKind::Int;
  else return ParamKind::Float;
}

template <typename T>
T from_double(double v) {
  if constexpr (std::is_same_v<T, bool>) return v != 0.0;
  else if constexpr (std::is_enum_v<T>) return static_cast<T>(static_cast<std::underlying_type_t<T>>(std::llround(v)));
  else if constexpr (std::is_integral_v<T>) return static_cast<T>(std::llround(v));
  else return static_cast<T>(v);
}

template <typename T>
double to_double(T v) {
  if constexpr (std::is_enum_v<T>) return double(static_cast<std::underlying_type_t<T>>(v));
  else return double(v);
}

// One row: the accessors are generated from the member path, so defaults and types are never repeated.
#define WB_PARAM(path, label, unit, paper, lo, hi, tip)                                                    \
  ParamInfo {                                                                                             \
    #path, label, unit, paper, tip, kind_of<std::remove_cvref_t<decltype(SimParams{}.path)>>(), lo, hi,   \
        [](const SimParams& p) { return to_double(p.path); },                                             \
        [](SimParams& p, double v) { p.path = from_double<std::remove_cvref_t<decltype(p.path)>>(v); }    \
  }

std::vector<ParamInfo> build_table() {
  return {
      // Brush solver (§4.1).
      WB_PARAM(brush_solver.iterations, "Constraint sweeps", "", "§4.1", 1, 100,
               "Gauss-Seidel sweeps of the inextensibility, bending and collision constraints per step"),
      WB_PARAM(brush_solver.density_iterations, "Minimum-density iterations", "", "§4.1", 0, 20,
               "Iterations of the minimum-density constraint that keeps bristles from collapsing (0 = off)"),
      WB_PARAM(brush_solver.damping, "Bristle damping", "1/s", "", 0, 1000,
               "Decay rate of the brush-frame velocity: exp(-rate t), whatever the sub-step count"),
      WB_PARAM(brush_solver.min_spacing, "Minimum bristle spacing", "cells", "§4.1", -1, 10,
               "Spacing the minimum-density constraint keeps; negative = twice the bristle radius"),
      WB_PARAM(bristle_drag, "Paint drag on bristles", "1/s", "Eq. 2", 0, 1000,
               "How fast bristles take the velocity of the paint they move through"),
      // Grid (§4.2, Algorithm 1).
      WB_PARAM(grid.solver, "Pressure solver", "", "§4.2", 0, 3,
               "0 fixed-point (Alg. 1), 1 Jacobi, 2 weighted Jacobi, 3 Chebyshev"),
      WB_PARAM(grid.jacobi_L, "Fixed-point iterations L", "", "Alg. 1", 0, 1000,
               "Fixed-point iterations of Algorithm 1, two Jacobi sweeps each"),
      WB_PARAM(grid.alpha, "Fixed-point alpha", "", "Eq. 3", 0, 1, "Restart weight of Algorithm 1"),
      WB_PARAM(grid.solver_sweeps, "Solver sweeps", "", "§4.2", 0, 10000,
               "Sweeps of the Jacobi, weighted Jacobi and Chebyshev solvers"),
      WB_PARAM(grid.jacobi_omega, "Jacobi weight", "", "Eq. 7", 0.01, 1, "Weight of weighted Jacobi"),
      WB_PARAM(grid.chebyshev_rho, "Chebyshev rho", "", "Eq. 6", 0, 0.9999,
               "Spectral-radius estimate for Chebyshev; 0 = estimate by power iteration"),
      WB_PARAM(grid.yield_stress_stiff, "Yield stress, no oil", "Pa", "", 0, 1e4,
               "Herschel-Bulkley yield stress of paint without oil: below it paint holds its shape"),
      WB_PARAM(grid.yield_stress_oily, "Yield stress of oil", "Pa", "", 0, 1e4,
               "Yield stress at oil fraction 1; oil fractions between interpolate geometrically"),
      WB_PARAM(grid.consistency_stiff, "Consistency, no oil", "Pa s^n", "", 1e-4, 1e5,
               "Herschel-Bulkley consistency K of paint without oil"),
      WB_PARAM(grid.consistency_oily, "Consistency of oil", "Pa s^n", "", 1e-4, 1e5,
               "Consistency K at oil fraction 1 (linseed oil: about 0.05 Pa s)"),
      WB_PARAM(grid.flow_index_stiff, "Flow index, no oil", "", "", 0.05, 1,
               "Herschel-Bulkley exponent n of paint without oil (< 1: shear-thinning)"),
      WB_PARAM(grid.flow_index_oily, "Flow index of oil", "", "", 0.05, 1, "Exponent n at oil fraction 1"),
      WB_PARAM(grid.regularisation, "Yield regularisation", "s", "", 1, 1e5,
               "Papanastasiou m: below the strain rate 1/m unyielded paint creeps at viscosity tau_y m"),
      WB_PARAM(grid.viscosity_tolerance, "Viscous solve tolerance", "", "", 1e-7, 1,
               "Relative residual at which the conjugate-gradient viscosity solve stops"),
      WB_PARAM(grid.viscosity_max_iterations, "Viscous solve iterations", "", "", 0, 10000,
               "Most conjugate-gradient iterations of the viscosity solve per step (0 = no viscosity)"),
      WB_PARAM(grid.gravity, "Gravity", "cells/s^2", "Eq. 2", 0, 1e6, "Gravity on the grid paint (down)"),
      WB_PARAM(grid.film_max, "Thin film", "cells", "", 0, 4,
               "Wet paint at most this thick, away from the bristles, flows as a film under gravity (0: off)"),
      WB_PARAM(grid.surface_tension, "Surface tension", "N/m", "", 0, 0.1,
               "Levels a thin film's grooves where its stress passes the yield stress (linseed oil: 0.033; 0: off)"),
      WB_PARAM(grid.tilt, "Canvas tilt", "degrees", "", 0, 90,
               "0: flat on a table; 90: upright on an easel (gravity pulls the paint down the canvas, +y)"),
      WB_PARAM(grid.liquid_threshold, "Liquid threshold", "", "§4.2", 0.01, 1,
               "Density at and above which a cell takes part in the projection"),
      WB_PARAM(grid.dry_rate, "Drying rate", "1/s", "§4.2", 0, 1000, "Dryness added per second"),
      WB_PARAM(grid.dry_threshold, "Dry threshold", "", "§4.2", 0.01, 1,
               "Dryness at and above which paint is solid"),
      WB_PARAM(grid.rest_speed, "Rest speed", "cells/s", "", 0, 100,
               "Paint slower than this everywhere is at rest: a replay passes over a pen-up pause in one call, drying only"),
      WB_PARAM(grid.projection_norms, "Projection norms", "", "", 0, 1,
               "Measure the divergence before and after each projection (two reductions a step)"),
      WB_PARAM(grid.window_snap, "Window snap", "cells", "§4.2", 1, 64,
               "The active window moves in steps of this many cells"),
      // Particles (§4.3, Table 1).
      WB_PARAM(particles.beta_L, "beta_L", "", "Eq. 9", 0, 0.2,
               "Inertial weight in the bristle-sample frame: small = particles stick to bristles"),
      WB_PARAM(particles.D1, "Adhesion range D1", "cells", "Eq. 10", 0, 100,
               "Distance to the bristles within which the local-frame result is blended in"),
      WB_PARAM(particles.D0, "Particle range D0", "cells", "§5.2", 0, 200,
               "Paint within this distance of the bristles is simulated as particles"),
      WB_PARAM(particles.delta, "Friction range delta", "1/cells", "Eq. 8", 0.01, 1,
               "Friction vanishes beyond 1/delta from a solid surface"),
      WB_PARAM(particles.friction_rate, "Friction rate k", "1/s", "Eq. 8", 0, 1e6,
               "How fast paint touching the canvas stops: its velocity decays as exp(-k w t)"),
      WB_PARAM(particles.gamma, "PIC weight gamma", "", "Eq. 11", 0, 1,
               "Weight of the projected grid velocity in the particle velocity update"),
      WB_PARAM(particles.sample_cell, "Sample grid cell", "cells", "§6", 1, 100, "Cell size of the sample grid"),
      WB_PARAM(particles.max_particles, "Particle limit", "", "§7", 1, 2147483647.0, "Most particles at once"),
      // Rendering (§6).
      // Liquid transfer (§5) and wicking.
      WB_PARAM(transfer.mu, "Capacity compression mu", "", "Eq. 12", 0, 1, "How much bristle crowding cuts a sample's capacity"),
      WB_PARAM(transfer.M_max, "Sample capacity M_max", "kg", "Eq. 12", 1e-12, 1e-5, "Most paint one bristle sample holds, for a bristle of 0.25 cells (scaled by the radius cubed)"),
      WB_PARAM(transfer.epsilon, "Emission epsilon", "", "§5.1", 0, 10, "A sample emits above (1 + epsilon) M_j"),
      WB_PARAM(transfer.absorb_limit, "Absorb limit", "", "§5.1", 0, 1024, "Particles one sample absorbs per step"),
      WB_PARAM(transfer.emit_limit, "Emit limit", "", "§5.1", 0, 64, "Particles one sample emits per step"),
      WB_PARAM(transfer.bleed, "Colour bleeding", "", "§5.1", 0, 1, "Colour exchanged with particles a full sample does not absorb"),
      WB_PARAM(transfer.split, "Film split", "", "Eq. 13", 0, 1,
               "Share of the paint a sliding bristle sweeps over a surface that stays there (0: the paper's model)"),
      WB_PARAM(transfer.candidate_split, "Candidates per cell axis", "", "§5.2", 1, 3,
               "A cell near the bristles is sampled into up to this cubed particles a step (the paper: 3, 27 candidates)"),
      WB_PARAM(transfer.slow_speed, "Slow speed", "cells/s", "§5.2", 0, 1e4, "Particles slower than this go back to the grid"),
      WB_PARAM(transfer.return_margin, "Return margin", "cells", "§5.2", 0, 100, "Particles go back to the grid only this far beyond D0"),
      WB_PARAM(transfer.distance_block, "Distance block", "cells", "§5.2", 1, 16,
               "Edge of the blocks the distance to the bristles (D0) is measured on"),
      WB_PARAM(transfer.wick_rate, "Wicking", "1/s", "", 0, 1e6, "Capillary flow of paint along a bristle towards its emptier samples"),
      WB_PARAM(transfer.wick_slide, "Drag pumping", "1/cell", "", 0, 1e5, "Paint drawn along a bristle towards its contact per cell the bristle slides"),
      WB_PARAM(transfer.dip_depth, "Dip depth", "of the length", "", 0, 1,
               "How far the brush is pushed into a well of paint, tip first, as a share of its bristles' length"),
      WB_PARAM(transfer.dip_exchange, "Dip exchange", "", "", 0, 1,
               "Share of the paint at a tip in the well that the well's paint replaces (0: a dip only tops up)"),
      WB_PARAM(render.step, "Ray step", "cells", "§6", 0.05, 2, "Ray-march step"),
      WB_PARAM(render.threshold, "Surface density", "", "§6", 0.01, 1, "Density at which the surface is found"),
      WB_PARAM(render.penetration_per_oil, "Oil penetration", "cells", "§6", 0, 100,
               "How far below the surface pigment is gathered, per unit of oil"),
      WB_PARAM(render.film_hiding, "Film hiding", "cells", "", 0.01, 100,
               "Paint this thick hides all but 2 % of the canvas; thinner films let it through"),
      WB_PARAM(render.ao_rays, "AO rays", "", "§6", 0, 256, "Ambient-occlusion rays per hit"),
      WB_PARAM(render.ao_length, "AO length", "cells", "§6", 0, 64, "How far an AO ray looks"),
      WB_PARAM(render.ao_strength, "AO strength", "", "§6", 0, 1, "How dark full occlusion makes the ambient"),
      WB_PARAM(render.light_dir.x, "Light x", "", "", -1, 1, "Direction towards the light, x"),
      WB_PARAM(render.light_dir.y, "Light y", "", "", -1, 1, "Direction towards the light, y"),
      WB_PARAM(render.light_dir.z, "Light z", "", "", 0.05, 1, "Direction towards the light, z (up)"),
      WB_PARAM(render.ambient, "Ambient", "", "", 0, 2, "Ambient light"),
      WB_PARAM(render.diffuse, "Diffuse", "", "", 0, 2, "Directional light"),
      WB_PARAM(render.specular, "Wet specular", "", "", 0, 2, "Specular of wet paint; fades as it dries"),
      WB_PARAM(render.shininess, "Shininess", "", "", 1, 1000, "Blinn-Phong exponent"),
  };
}
#undef WB_PARAM

}  // namespace

const std::vector<ParamInfo>& param_table() {
  static const std::vector<ParamInfo> table = build_table();
  return table;
}

const ParamInfo* find_param(const std::string& id) {
  for (const ParamInfo& p : param_table())
    if (p.id == id) return &p;
  return nullptr;
}

void set_param(SimParams& p, const std::string& id, double value) {
  const ParamInfo* info = find_param(id);
  WB_REQUIRE(info, "unknown parameter '" + id + "' (see `wetbrush params`)");
  WB_REQUIRE(std::isfinite(value), "parameter " + id + ": value is not finite");
  if (info->kind != ParamKind::Float)
    WB_REQUIRE(value == std::floor(value), "parameter " + id + ": " + std::to_string(value) + " is not an integer");
  WB_REQUIRE(value >= info->min && value <= info->max, "parameter " + id + " = " + std::to_string(value) +
                                                          " is outside [" + std::to_string(info->min) + ", " +
                                                          std::to_string(info->max) + "]");
  info->set(p, value);
}

void apply_param_assignment(SimParams& p, const std::string& assignment) {
  const size_t eq = assignment.find('=');
  WB_REQUIRE(eq != std::string::npos && eq > 0, "expected id=value, got '" + assignment + "'");
  const std::string id = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  double v = 0.0;
  if (text == "true") v = 1.0;
  else if (text == "false") v = 0.0;
  else {
    size_t used = 0;
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    WB_REQUIRE(used == text.size() && !text.empty(), "parameter " + id + ": '" + text + "' is not a number");
  }
  set_param(p, id, v);
}

nlohmann::json params_to_json(const SimParams& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const ParamInfo& info : param_table()) {
    nlohmann::json* node = &j;
    std::string rest = info.id;
    for (size_t dot; (dot = rest.find('.')) != std::string::npos; rest = rest.substr(dot + 1))
      node = &(*node)[rest.substr(0, dot)];
    const double v = info.get(p);
    if (info.kind == ParamKind::Bool) (*node)[rest] = v != 0.0;
    else if (info.kind == ParamKind::Int) (*node)[rest] = static_cast<long long>(v);
    else (*node)[rest] = v;
  }
  return j;
}

void params_from_json(SimParams& p, const nlohmann::json& j, std::vector<std::string>& warnings) {
  // No parameter id has more levels than the table's deepest one, so the walk never descends
  // further: a file nesting objects a million deep is one warning, not a stack overflow.
  static const int max_levels = [] {
    int m = 1;
    for (const ParamInfo& info : param_table())
      m = std::max(m, 1 + int(std::count(info.id.begin(), info.id.end(), '.')));
    return m;
  }();
  std::function<void(const nlohmann::json&, const std::string&, int)> walk = [&](const nlohmann::json& node,
                                                                                  const std::string& prefix, int level) {
    WB_REQUIRE(node.is_object(), "parameters: '" + prefix + "' must be an object");
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string id = prefix.empty() ? it.key() : prefix + "." + it.key();
      if (it->is_object()) {
        if (level + 1 < max_levels) walk(*it, id, level + 1);
        else warnings.push_back("unknown parameter group '" + id + "' ignored (no parameter is nested this deep)");
      } else if (find_param(id)) {
        WB_REQUIRE(it->is_number() || it->is_boolean(), "parameter " + id + ": expected a number");
        set_param(p, id, it->is_boolean() ? (it->get<bool>() ? 1.0 : 0.0) : it->get<double>());
      } else {
        warnings.push_back("unknown parameter '" + id + "' ignored");
      }
    }
  };
  walk(j, "", 0);
}

}  // namespace wb
