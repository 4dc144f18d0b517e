// White fit -> noise model -> GLS refit, for any instrument's problem (core/fit_with_noise.hpp).
#include "rotacal/core/fit_with_noise.hpp"

#include <memory>

namespace rotacal {

NoiseFitOutcome fit_with_noise(const ResidualModel& model, const std::vector<FitParameter>& parameters,
                               JointFitSettings settings, const std::vector<std::string>& groups,
                               const std::vector<double>& times, const NoiseFitOptions& options) {
  const auto n = static_cast<std::size_t>(model.num_residuals());
  if (groups.size() != n || times.size() != n)
    throw InvalidArgument("fit_with_noise: groups and times must hold one value per residual (" + std::to_string(n) +
                          "), got " + std::to_string(groups.size()) + " and " + std::to_string(times.size()));
  NoiseFitOutcome out;
  out.fit = solve_joint(model, parameters, settings);
  if (settings.whitener) return out;
  // With correlated noise the white covariance is too small by about sqrt(tau): the fit is
  // redone by GLS under the model of its residuals, from the same start (one feasible-GLS step).
  out.noise = estimate_noise_model(groups, times, out.fit.residuals, options.noise_options);
  if (options.noise != NoiseHandling::automatic || out.noise.white() ||
      out.noise.correlation_samples < options.min_correlation_samples)
    return out;
  if (options.noise_bias_correction)
    out.correction = noise_correction(out.noise, groups, times, out.fit, options.noise_options);
  settings.whitener = std::make_shared<ArWhitener>(out.noise);
  out.fit = solve_joint(model, parameters, settings);
  apply_noise_correction(out.correction, &out.fit);
  out.refit = true;
  out.note = "correlated noise (" + out.noise.summary() + "): covariance by GLS under this AR model, scaled by " +
             std::to_string(out.correction) + " for the correlation the fit absorbs from its residuals";
  return out;
}

}  // namespace rotacal
