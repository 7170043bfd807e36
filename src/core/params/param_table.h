// The parameter table: one row per tunable of SimParams with its id, label, unit, range,
// tooltip and paper reference. It drives `--set id=value` on the CLI, the JSON I/O of
// parameter files, validation, and the studio's panels. Defaults come from SimParams{}.
#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/params/sim_params.h"

namespace wb {

enum class ParamKind { Float, Int, Bool };

struct ParamInfo {
  std::string id;       ///< "group.field", e.g. "grid.jacobi_L"
  std::string label;    ///< short human name
  std::string unit;     ///< "cells", "cells/s", "" for dimensionless
  std::string paper;    ///< "Eq. 9", "Alg. 1", "Table 1", or "" when not from the paper
  std::string tooltip;  ///< one sentence on what it does
  ParamKind kind = ParamKind::Float;
  double min = 0.0, max = 0.0;
  std::function<double(const SimParams&)> get;
  std::function<void(SimParams&, double)> set;
  double default_value() const { return get(SimParams{}); }
};

const std::vector<ParamInfo>& param_table();
/// The row of `id`, or null.
const ParamInfo* find_param(const std::string& id);
/// Sets one parameter after checking it exists, is finite, integral where it must be,
/// and in range; throws wb::Error with the id, the value and the range otherwise.
void set_param(SimParams& p, const std::string& id, double value);
/// Parses "id=value" (value: a number, true or false).
void apply_param_assignment(SimParams& p, const std::string& assignment);

/// {"grid": {"jacobi_L": 3, ...}, ...}: every parameter.
nlohmann::json params_to_json(const SimParams& p);
/// Reads a (possibly partial) parameter object; unknown keys become warnings, bad values errors.
void params_from_json(SimParams& p, const nlohmann::json& j, std::vector<std::string>& warnings);

}  // namespace wb
