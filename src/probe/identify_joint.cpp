// SPDX-License-Identifier: BSD-3-Clause
// Joint fit of a touch-probe session through the one driver with its noise model.
#include <cmath>

#include "rotacal/core/time_constant_fit.hpp"
#include "rotacal/probe/identify.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/touch_noise.hpp"

namespace rotacal {

const ParameterEstimate& ProbeIdentification::parameter(const std::string& name) const {
  for (const ParameterEstimate& p : parameters)
    if (p.name == name) return p;
  throw InvalidArgument("no identified parameter named '" + name + "'");
}

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
  JointFitOutcome& fit = nf.fit;

  ProbeIdentification out;
  out.method = "joint";
  out.model.machine = session.machine;
  out.model.errors = LocationErrors<double>(L.errors.of<8>(fit.values));
  out.model.effects = problem.effects();
  const auto fx = L.effects.of(fit.values);
  out.model.effect_params.assign(fx.data(), fx.data() + fx.size());
  out.sphere = L.sphere.of<3>(fit.values);
  out.converged = fit.summary.converged;
  out.iterations = fit.summary.iterations;
  out.n_samples = session.samples.size();
  out.residuals.assign(fit.residuals.data(), fit.residuals.data() + fit.residuals.size());
  const double n = static_cast<double>(fit.residuals.size());
  out.residual_rms_um = std::sqrt(fit.residuals.squaredNorm() / n) * 1e3;
  out.sigma_um = std::sqrt(fit.residual_variance) * 1e3;
  if (settings.whitener || nf.refit)  // the noise level the covariance rests on
    out.sigma_um =
        std::sqrt(fit.residuals.squaredNorm() / std::max(1.0, n - fit.summary.num_free)) * 1e3;
  out.covariance = std::move(fit.covariance);
  out.jacobian = std::move(fit.jacobian);
  for (bool f : fit.free) out.fixed.push_back(!f);
  out.parameters = std::move(fit.estimates);
  out.unobservable = std::move(fit.unobservable);
  out.summary = fit.summary;
  out.noise = std::move(nf.noise);
  out.noise_refit = nf.refit;
  out.noise_correction = nf.scale;
  out.notes.push_back(
      "calibrated trigger radius (sphere_diameter + stylus_diameter) / 2 = " +
      std::to_string(session.trigger_radius()) +
      " mm taken as given; a wrong stylus radius is the diagnosis' stylus_radius_offset");
  if (nf.refit)
    out.notes.push_back("correlated noise (" + out.noise.summary() +
                        ", each machine coordinate's from one touch to the next, seen along "
                        "the approach; REML over what the fit leaves): covariance by GLS under "
                        "this model");
  if (!out.converged) out.notes.push_back("the fit did not converge: " + fit.summary.message);
  return out;
}

}  // namespace rotacal
