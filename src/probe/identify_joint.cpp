// SPDX-License-Identifier: BSD-3-Clause
// Joint fit of a touch-probe session through the one driver with its noise model.
#include <cmath>

#include "rotacal/core/time_constant_fit.hpp"
#include "rotacal/probe/identify.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/touch_noise.hpp"

namespace rotacal {

ProbeIdentification identify_probe(const ProbeSession& session, const ProbeFitOptions& options) {
  const ProbeProblem problem(session, options.effects);
  const ProbeParameterLayout& L = problem.layout();
  if (problem.num_residuals() <= problem.num_parameters())
    throw InvalidArgument("identify_probe: session: " + std::to_string(problem.num_residuals()) +
                          " touches cannot determine " + std::to_string(problem.num_parameters()) +
                          " unknowns");
  JointFitSettings settings;
  settings.max_iterations = options.max_iterations;
  settings.observability_min_chi2 = options.observability_min_chi2;
  settings.sigma = session.noise_um.value_or(1.0) * 1e-3;  // scales chi-square only
  settings.whitener = options.whitener;
  const std::vector<FitParameter> parameters = problem.parameters();
  NoiseFitOptions noise = options.noise;
  if (!noise.own_noise && noise.noise == NoiseHandling::automatic)
    noise.own_noise = touch_noise_model(std::make_shared<const ProbeSession>(session));
  NoiseFit nf = fit_with_noise(
      [&](const JointFitSettings& s) { return solve_with_time_constants(problem, parameters, s); },
      settings, problem.groups(), problem.times(), noise);
  // The touch model's own words where it refitted (REML, no bias factor), else the shared note.
  const std::string gls_note =
      nf.refit ? "correlated noise (" + nf.noise.summary() +
                     ", each machine coordinate's from one touch to the next, seen along the "
                     "approach; REML over what the fit leaves): covariance by GLS under this model"
               : noise_refit_note(nf);
  const Eigen::VectorXd values = nf.fit.values;
  ProbeIdentification out;
  static_cast<Identification&>(out) =
      joint_identification(std::move(nf), L.all, settings.whitener != nullptr);
  out.model.machine = session.machine;
  out.model.errors = LocationErrors<double>(L.errors.of<8>(values));
  out.model.effects = problem.effects();
  const auto fx = L.effects.of(values);
  out.model.effect_params.assign(fx.data(), fx.data() + fx.size());
  out.sphere = L.sphere.of<3>(values);
  out.n_samples = session.samples.size();
  out.notes.push_back(
      "calibrated trigger radius (sphere_diameter + stylus_diameter) / 2 = " +
      std::to_string(session.trigger_radius()) +
      " mm taken as given; a wrong stylus radius is the diagnosis' stylus_radius_offset");
  if (!gls_note.empty()) out.notes.push_back(gls_note);
  if (!out.converged) out.notes.push_back("the fit did not converge: " + out.summary.message);
  return out;
}

}  // namespace rotacal
