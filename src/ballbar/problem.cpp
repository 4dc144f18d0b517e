// SPDX-License-Identifier: BSD-3-Clause
// The ballbar problem's layout and fit set-up (ballbar/problem.hpp).
#include "rotacal/ballbar/problem.hpp"

#include <algorithm>

namespace rotacal {

BallbarLayout ballbar_layout(MachineType m, const EffectModel& fx, int pivots) {
  if (pivots < 1)
    throw InvalidArgument("ballbar_layout: pivots is " + std::to_string(pivots) + ", must be >= 1");
  BallbarLayout L;
  L.errors = add_location_errors(L.all, m);
  std::vector<std::string> names;
  const char* axis = "xyz";
  for (int s = 0; s < pivots; ++s)
    for (int k = 0; k < 3; ++k)
      names.push_back(std::string("pivot_") + axis[k] +
                      (pivots > 1 ? "#" + std::to_string(s + 1) : ""));
  L.pivots = L.all.add("pivot", std::move(names), {"mm"}, 3);
  L.effects = add_effects(L.all, fx);
  return L;
}

BallbarFitSetup ballbar_fit_setup(const BallbarArrays& data, const JointFitOptions& options) {
  BallbarFitSetup out;
  EffectModel& fx = out.effects;
  fx = options.effects;
  if (!fx.linear_reference && data.size() > 0)
    fx.linear_reference = Eigen::Vector3d(data.xyz.rowwise().mean());
  if (options.fit_length_offset)
    fx.effects.insert(fx.effects.begin(), Effect::parse("ballbar_length_offset"));
  // On a machine with head axes the ball's distance from the controlled point,
  // pivot_length + tool_length, is a location parameter of the head (formats.md): its error
  // is fitted as tool_offset_Z, which there acts along the spindle (kinematics/effects.hpp).
  const Effect tool_z = Effect::parse("tool_offset_Z");
  if (data.machine.has_head() &&
      std::find(fx.effects.begin(), fx.effects.end(), tool_z) == fx.effects.end())
    fx.effects.insert(fx.effects.begin(), tool_z);
  for (const Effect& f : fx.effects)
    if (!f.applies_to(data.machine))
      throw InvalidArgument("effect " + f.id() + " does not exist on a " + to_string(data.machine));
  out.layout = ballbar_layout(data.machine, fx);
  const BallbarLayout& L = out.layout;
  if (static_cast<Eigen::Index>(data.size()) < L.all.size())
    throw InvalidArgument("identify_joint: " + std::to_string(data.size()) +
                          " samples cannot determine " + std::to_string(L.all.size()) +
                          " unknowns");
  // Names, units and start values of the unknowns, in Jacobian column order: zero errors and
  // the nominal pivot.
  const std::vector<std::string> names = L.all.names(), units = L.all.units();
  std::vector<FitParameter>& params = out.parameters;
  for (Eigen::Index j = 0; j < L.all.size(); ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    params.push_back(
        {names[k], units[k], L.pivots.contains(j) ? data.pivot[j - L.pivots.offset] : 0.0});
  }
  // Catalogue effects yield to the baseline where they share directions with it
  // (core/yield_convention.hpp); the head's tool length is part of the baseline.
  Eigen::Index j = L.effects.offset;
  for (const Effect& f : fx.effects) {
    const bool yields = !(data.machine.has_head() && f == tool_z);
    for (int k = 0; k < f.num_params(); ++k) params[static_cast<std::size_t>(j++)].yields = yields;
  }
  out.settings.max_iterations = options.max_iterations;
  out.settings.observability_min_chi2 = options.observability_min_chi2;
  // sigma scales chi-square (observability); the covariance uses the residual variance.
  out.settings.sigma = data.noise_um.value_or(1.0) * 1e-3;
  out.settings.whitener = options.whitener;
  return out;
}

BallbarMachineModel ballbar_model_at(const BallbarFitSetup& setup, MachineType m,
                                     const Eigen::VectorXd& x) {
  const BallbarLayout& L = setup.layout;
  BallbarMachineModel out;
  out.machine = m;
  out.errors = LocationErrors<double>(L.errors.of<8>(x));
  out.pivot = L.pivots.item(0).of<3>(x);
  out.effects = setup.effects;
  const auto e = L.effects.of(x);
  out.effect_params.assign(e.data(), e.data() + e.size());
  return out;
}

}  // namespace rotacal
