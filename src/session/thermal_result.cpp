// SPDX-License-Identifier: BSD-3-Clause
// The one thermal fit and its result, for every instrument (session/thermal_result.hpp).
#include "rotacal/session/thermal_result.hpp"

#include <algorithm>
#include <cmath>

#include "rotacal/core/time_constant_fit.hpp"

namespace rotacal {

namespace {
// Why a gain the driver held is not determined.
std::string gain_reason(bool heated, int cold, const ThermalIdentification& out) {
  if (!heated) return "no heat input: the duty never turns the axis between the epochs";
  if (cold >= 0 && !out.cold[static_cast<std::size_t>(cold)].observable)
    return "the poses do not determine " + out.cold[static_cast<std::size_t>(cold)].name +
           " itself";
  return "the epochs do not separate it from the cold value and the other gains (the poses, "
         "a test too short or epochs too sparse for the lag)";
}
}  // namespace

NoiseFit fit_thermal(const ResidualModel& model, std::vector<FitParameter> params,
                     const ThermalFitIndex& index, bool heated, const JointFitSettings& settings,
                     const std::vector<std::string>& groups, const std::vector<double>& times,
                     const ThermalFitOptions& options) {
  if (options.lags < 1 || options.lags > 2)
    throw InvalidArgument("thermal identification: lags must be 1 or 2, got " +
                          std::to_string(options.lags));
  if (model.num_residuals() <= model.num_parameters())
    throw InvalidArgument("thermal identification: " + std::to_string(model.num_residuals()) +
                          " residuals cannot determine " + std::to_string(model.num_parameters()) +
                          " unknowns");
  for (std::size_t l = 0; l < index.tau.size(); ++l) {
    FitParameter& q = params[static_cast<std::size_t>(index.tau[l])];
    q.start = std::log(options.tau_start_s * (l == 0 ? 1.0 : 4.0) / 300.0);
    q.held = !heated;  // without heat input tau moves nothing
    for (std::size_t k = 0; k < index.gain_names.size() && !heated; ++k)
      params[static_cast<std::size_t>(index.gains[l]) + k].held = true;
  }
  return fit_with_noise(
      [&](const JointFitSettings& s) { return solve_with_time_constants(model, params, s); },
      settings, groups, times, options.noise);
}

ThermalIdentification thermal_identification(const NoiseFit& nf, const ThermalFitIndex& index,
                                             bool heated) {
  const JointFitOutcome& fit = nf.fit;
  ThermalIdentification out;
  const auto est = [&](int j, const std::string& name) {
    const ParameterEstimate& p = fit.estimates[static_cast<std::size_t>(j)];
    return ThermalGainEstimate{
        name, p.unit, p.value, p.std, p.observable && fit.free[static_cast<std::size_t>(j)], ""};
  };
  for (std::size_t k = 0; k < index.cold.size(); ++k)
    out.cold.push_back(est(index.cold[k], index.cold_names[k]));
  for (std::size_t l = 0; l < index.tau.size(); ++l) {
    ThermalLag lag;
    const int jq = index.tau[l];
    const ParameterEstimate& q = fit.estimates[static_cast<std::size_t>(jq)];
    lag.tau_s = 300.0 * std::exp(fit.values[jq]);
    lag.tau_std_s = lag.tau_s * q.std;  // tau = 300 s e^q: d tau = tau dq
    lag.tau_observable = fit.free[static_cast<std::size_t>(jq)] && q.observable;
    out.tau_index.push_back(jq);
    out.gain_index.push_back(index.gains[l]);
    for (std::size_t k = 0; k < index.gain_names.size(); ++k) {
      ThermalGainEstimate g = est(index.gains[l] + static_cast<int>(k), index.gain_names[k]);
      if (!g.observable) g.reason = gain_reason(heated, index.gain_cold[k], out);
      lag.gains.push_back(g);
    }
    out.lags.push_back(std::move(lag));
  }
  out.parameters = fit.estimates;
  out.covariance = fit.covariance;
  out.unobservable = fit.unobservable;
  out.converged = fit.summary.converged;
  out.residual_rms_um =
      std::sqrt(fit.residuals.squaredNorm() / static_cast<double>(fit.residuals.size())) * 1e3;
  if (nf.refit) out.noise = nf.noise.summary();
  // The covariance rests on s^2 (white) or on the noise model (coloured), each estimated from
  // the residuals: so many samples, or effective samples, less the free parameters.
  double free = 0.0;
  for (std::size_t j = 0; j < fit.free.size(); ++j)
    free += fit.free[j] && fit.estimates[j].observable;
  const double samples = nf.refit && nf.noise.effective_samples > 0.0
                             ? nf.noise.effective_samples
                             : static_cast<double>(fit.residuals.size());
  out.residual_dof = std::max(1.0, samples - free);
  if (!out.converged) out.notes.push_back("the fit did not converge: " + fit.summary.message);
  if (!heated) out.notes.push_back("no duty: an ordinary session, its thermal gains unobservable");
  return out;
}

}  // namespace rotacal
