// SPDX-License-Identifier: BSD-3-Clause
// The two-stage joint fit of a model with time constants (core/time_constant_fit.hpp).
#include "rotacal/core/time_constant_fit.hpp"

namespace rotacal {

JointFitOutcome solve_with_time_constants(const ResidualModel& model,
                                          std::vector<FitParameter> params,
                                          const JointFitSettings& settings) {
  std::vector<std::size_t> gated;
  for (std::size_t j = 0; j < params.size(); ++j)
    if (params[j].unit == "1" && !params[j].held) gated.push_back(j);
  if (gated.empty()) return solve_joint(model, params, settings);
  for (std::size_t j : gated) params[j].held = true;
  const JointFitOutcome first = solve_joint(model, params, settings);
  for (std::size_t j = 0; j < params.size(); ++j)
    params[j].start = first.values[static_cast<Eigen::Index>(j)];
  for (std::size_t j : gated) params[j].held = false;
  return solve_joint(model, params, settings);
}

}  // namespace rotacal
