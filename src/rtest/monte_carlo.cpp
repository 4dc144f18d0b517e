// SPDX-License-Identifier: BSD-3-Clause
// Monte Carlo check of the R-test joint fit's 1-sigma with the session's fitted noise model.
#include "rotacal/rtest/monte_carlo.hpp"

#include <memory>

#include "rotacal/core/error.hpp"
#include "rotacal/core/monte_carlo.hpp"
#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

RtestMonteCarlo monte_carlo(const RtestSession& session, const RtestJointIdentification& result,
                            const RtestMonteCarloOptions& o) {
  if (o.draws < 2)
    throw InvalidArgument("monte_carlo: draws must be at least 2, got " + std::to_string(o.draws));
  const std::size_t n = session.samples.size();
  if (result.residuals.size() != 3 * n || result.n_samples != n)
    throw InvalidArgument("monte_carlo: result was fitted to " + std::to_string(result.n_samples) +
                          " samples, the session has " + std::to_string(n));
  RtestJointOptions fit = o.fit;
  fit.noise.noise = NoiseHandling::white;  // each draw is fitted as the identification was
  const bool coloured = result.noise_refit;
  if (coloured) fit.whitener = std::make_shared<ArWhitener>(result.noise);
  // The identified model's readings: measured - residual (probe zeros included).
  std::vector<Eigen::Vector3d> model(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!session.samples[i].d)
      throw InvalidArgument("monte_carlo: session: sample " + std::to_string(i) +
                            " has no dx,dy,dz");
    model[i] = *session.samples[i].d - result.residual(i);
  }
  const int p = static_cast<int>(result.parameters.size());
  RtestMonteCarlo out;
  out.draws = o.draws;
  out.noise = coloured ? "the fitted noise model: " + result.noise.summary()
                       : "white noise, " + std::to_string(result.sigma_um) + " um";
  out.values.resize(o.draws, p);
  RtestSession s = session;
  for (int k = 0; k < o.draws; ++k) {
    const Eigen::VectorXd e = monte_carlo_noise(coloured, result.noise, result.sigma_um,
                                                3 * static_cast<Eigen::Index>(n), o.seed, k);
    for (std::size_t i = 0; i < n; ++i)
      s.samples[i].d = model[i] + e.segment<3>(3 * static_cast<Eigen::Index>(i));
    const RtestJointIdentification r = identify_joint(s, fit);
    if (static_cast<int>(r.parameters.size()) != p)
      throw InvalidArgument("monte_carlo: a draw's fit has " + std::to_string(r.parameters.size()) +
                            " parameters, the result " + std::to_string(p));
    for (int j = 0; j < p; ++j) out.values(k, j) = r.parameters[static_cast<std::size_t>(j)].value;
    if (o.progress) o.progress(k + 1, o.draws);
  }
  // The probe zeros are nuisance parameters: not compared.
  out.parameters =
      monte_carlo_summary(result.parameters, out.values,
                          [](const ParameterEstimate& e) { return e.name.rfind("zero.", 0) == 0; });
  return out;
}

}  // namespace rotacal
