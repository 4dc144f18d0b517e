// SPDX-License-Identifier: BSD-3-Clause
// Monte Carlo check of a touch-probe joint fit (probe/monte_carlo.hpp).
#include "rotacal/probe/monte_carlo.hpp"

#include <cmath>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/touch_noise.hpp"

namespace rotacal {

namespace {

// The session with touch i moved by shift[i] along its approach direction.
ProbeSession moved(const ProbeSession& session, const Eigen::VectorXd& shift) {
  ProbeSession out = session;
  for (std::size_t i = 0; i < out.samples.size(); ++i)
    out.samples[i].xyz += shift[static_cast<Eigen::Index>(i)] * session.samples[i].n.normalized();
  return out;
}

}  // namespace

ProbeMonteCarlo monte_carlo_probe(const ProbeSession& session, const ProbeIdentification& result,
                                  const ProbeMonteCarloOptions& o) {
  if (result.method != "joint" || result.model.machine != session.machine ||
      result.n_samples != session.samples.size())
    throw InvalidArgument("monte_carlo_probe: result is not a joint fit of this session (method " +
                          result.method + ", " + std::to_string(result.n_samples) + " touches)");
  if (o.draws < 2)
    throw InvalidArgument("monte_carlo_probe: draws must be at least 2, got " +
                          std::to_string(o.draws));
  // The identified machine, and how each touch's residual changes as the touch moves along its
  // direction (a forward difference; the residual is linear in the shift over micrometres).
  const EffectModel& fx = result.model.effects;  // centred on this session by the fit
  Eigen::VectorXd x(static_cast<Eigen::Index>(result.parameters.size()));
  for (std::size_t j = 0; j < result.parameters.size(); ++j)
    x[static_cast<Eigen::Index>(j)] = result.parameters[j].value;
  const Eigen::Index n = static_cast<Eigen::Index>(session.samples.size());
  const Eigen::VectorXd r0 = ProbeProblem(session, fx).residuals(x);
  const double h = 1e-4;  // mm
  const Eigen::VectorXd slope =
      (ProbeProblem(moved(session, Eigen::VectorXd::Constant(n, h)), fx).residuals(x) - r0) / h;
  if (!(slope.array().abs() > 0.1).all())
    throw InvalidArgument(
        "monte_carlo_probe: a touch's residual does not change along its approach direction");

  ProbeMonteCarlo out;
  out.draws = o.draws;
  out.noise_um = result.sigma_um;
  const bool coloured = result.noise_refit;
  const bool touch =
      coloured && result.noise.streams.size() == 1 && result.noise.streams.front().ar.size() == 1;
  const double touch_rho = touch ? result.noise.streams.front().ar.front() : 0.0;
  if (coloured && !touch)
    throw InvalidArgument("monte_carlo_probe: the fit's noise model is not the touch probe's (" +
                          result.noise.summary() + ")");
  out.noise = coloured ? "the fitted noise model: " + result.noise.summary() : "white noise";
  ProbeFitOptions fit;
  fit.effects = fx;
  fit.noise.noise = o.noise;
  out.values.resize(o.draws, static_cast<Eigen::Index>(result.parameters.size()));
  for (int k = 0; k < o.draws; ++k) {
    // The noise the fit assumed: the touch model's (probe/touch_noise.hpp) where it is coloured.
    std::mt19937_64 rng(o.seed + static_cast<std::uint64_t>(k));
    const Eigen::VectorXd e =
        touch ? draw_touch_noise(session, touch_rho, result.noise.sigma_um * 1e-3, rng)
              : monte_carlo_noise(false, result.noise, result.sigma_um, n, o.seed, k);
    // Each touch where the identified machine leaves the drawn noise as its residual.
    const ProbeSession draw = moved(session, ((e - r0).array() / slope.array()).matrix());
    const ProbeIdentification r = identify_probe(draw, fit);
    for (std::size_t j = 0; j < r.parameters.size(); ++j)
      out.values(k, static_cast<Eigen::Index>(j)) = r.parameters[j].value;
    if (o.progress) o.progress(k + 1, o.draws);
  }
  out.parameters = monte_carlo_summary(result.parameters, out.values);
  return out;
}

}  // namespace rotacal
