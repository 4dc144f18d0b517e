// SPDX-License-Identifier: BSD-3-Clause
// Monte Carlo check of the ballbar joint fit's 1-sigma, reusing one prepared problem.
#include "rotacal/ballbar/monte_carlo.hpp"

#include <cmath>
#include <memory>

#include "length_model.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/monte_carlo.hpp"
#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

BallbarMonteCarlo monte_carlo(const BallbarSession& session, const BallbarIdentification& result,
                              const BallbarMonteCarloOptions& o) {
  if (result.method != "joint")
    throw InvalidArgument("monte_carlo: result: method '" + result.method +
                          "' (only a joint fit is supported)");
  if (result.model.machine != session.machine)
    throw InvalidArgument("monte_carlo: result is for a " + to_string(result.model.machine) +
                          " but the session is for a " + to_string(session.machine));
  if (o.draws < 2)
    throw InvalidArgument("monte_carlo: draws must be at least 2, got " + std::to_string(o.draws));
  if (!(o.noise_um >= 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("monte_carlo: noise_um must be finite and >= 0");
  JointFitOptions fit_options = o.fit;
  fit_options.effects = result.model.effects;  // the identified model's effects, in its order
  fit_options.fit_length_offset = false;       // already among them if it was fitted
  // A GLS identification is checked the way it was made: each draw refitted under the same
  // noise model's whitener (its covariance factor is in the reported sigma).
  const bool coloured = result.noise_refit && !fit_options.whitener && !o.noise;
  if (result.noise_refit && !fit_options.whitener)
    fit_options.whitener = std::make_shared<ArWhitener>(result.noise);
  BallbarArrays data = ballbar_arrays(session, fit_options.tests);
  if (static_cast<std::size_t>(data.size()) != result.n_samples ||
      result.residuals.size() != session.samples.size())
    throw InvalidArgument("monte_carlo: result was fitted to " + std::to_string(result.n_samples) +
                          " samples, the session (with fit.tests) has " +
                          std::to_string(data.size()));
  const BallbarFitSetup setup = ballbar_fit_setup(data, fit_options);
  const int p = static_cast<int>(setup.parameters.size());
  if (static_cast<int>(result.parameters.size()) != p || result.jacobian.cols() != p)
    throw InvalidArgument("monte_carlo: result has " + std::to_string(result.parameters.size()) +
                          " parameters, its model implies " + std::to_string(p));

  // The reference linearisation: the identified solution, its Jacobian and free set.
  JointFitOutcome reference;
  reference.values.resize(p);
  for (int j = 0; j < p; ++j)
    reference.values[j] = result.parameters[static_cast<std::size_t>(j)].value;
  reference.jacobian = result.jacobian;
  for (bool f : result.fixed) reference.free.push_back(!f);
  const JointRefitter refitter(reference, setup.parameters, setup.settings);

  const double noise_um = o.noise_um > 0.0 ? o.noise_um : result.sigma_um;
  const std::vector<double> truth_all = predict_lengths(result.model, session.samples);
  Eigen::VectorXd truth(data.size());
  for (Eigen::Index k = 0; k < data.size(); ++k)
    truth[k] = truth_all[data.index[static_cast<std::size_t>(k)]];
  const BallbarLengthModel model(data, setup.effects);

  BallbarMonteCarlo out;
  out.draws = o.draws;
  out.noise_um = noise_um;
  out.noise = o.noise    ? "the caller's noise"
              : coloured ? "the fitted noise model: " + result.noise.summary()
                         : "white noise";
  out.values.resize(o.draws, p);
  Eigen::VectorXd noise(data.size());
  for (int k = 0; k < o.draws; ++k) {
    if (o.noise) {
      noise.setZero();
      o.noise(k, noise);
    } else if (coloured) {  // AR draws per stream from the model fitted to the session
      noise = monte_carlo_noise(true, result.noise, noise_um, data.size(), o.seed, k);
    } else {  // as simulate_ballbar(session, model, {noise_um, seed + k}) draws it: one value
              // per session sample, in order, of which the fitted samples are taken
      const Eigen::VectorXd all =
          monte_carlo_noise(false, result.noise, noise_um,
                            static_cast<Eigen::Index>(session.samples.size()), o.seed, k);
      for (Eigen::Index i = 0; i < data.size(); ++i)
        noise[i] = all[static_cast<Eigen::Index>(data.index[static_cast<std::size_t>(i)])];
    }
    data.length = truth + noise;
    const JointRefitter::Result r = refitter.refit(model);
    out.fresh_fits += r.fell_back;
    out.values.row(k) = r.values.transpose();
    if (o.progress) o.progress(k + 1, o.draws);
  }
  out.parameters = monte_carlo_summary(result.parameters, out.values);
  return out;
}

}  // namespace rotacal
