// SPDX-License-Identifier: BSD-3-Clause
// The feasible-GLS sequence of the joint fits (core/fit_with_noise.hpp).
#include "rotacal/core/fit_with_noise.hpp"

#include <algorithm>
#include <memory>
#include <string>

namespace rotacal {

NoiseFit fit_with_noise(const std::function<JointFitOutcome(const JointFitSettings&)>& solve,
                        JointFitSettings settings, const std::vector<std::string>& groups,
                        const std::vector<double>& times, const NoiseFitOptions& o) {
  NoiseFit out;
  out.fit = solve(settings);
  if (settings.whitener || groups.empty()) return out;
  const auto n = static_cast<std::size_t>(out.fit.residuals.size());
  if (groups.size() != n || times.size() != n)
    throw InvalidArgument("fit_with_noise: groups and times must hold one value per residual (" +
                          std::to_string(n) + "), got " + std::to_string(groups.size()) + " and " +
                          std::to_string(times.size()));
  if (o.own_noise && o.noise == NoiseHandling::automatic) {
    std::shared_ptr<const ResidualWhitener> w = o.own_noise(out.fit, out.noise);
    if (!w) return out;
    settings.whitener = out.whitener = std::move(w);
    out.fit = solve(settings);
    out.refit = true;
    return out;
  }
  out.noise = estimate_noise_model(groups, times, out.fit.residuals, o.noise_options);
  if (o.noise != NoiseHandling::automatic || out.noise.white() ||
      out.noise.correlation_samples < o.min_correlation_samples)
    return out;
  std::size_t longest = 0;
  for (const NoiseStream& st : out.noise.streams) longest = std::max(longest, st.rows.size());
  out.reml = o.allow_reml && o.noise_options.reml_random_walk &&
             longest <= static_cast<std::size_t>(o.noise_options.reml_max_stream_size);
  if (out.reml)
    out.noise = estimate_noise_model_reml(out.noise, out.fit.residuals, free_jacobian(out.fit));
  else if (o.noise_bias_correction)
    out.scale = noise_correction(out.noise, groups, times, out.fit, o.noise_options);
  settings.whitener = out.whitener = std::make_shared<ArWhitener>(out.noise);
  out.fit = solve(settings);
  apply_noise_correction(out.scale, &out.fit);
  out.refit = true;
  return out;
}

}  // namespace rotacal
