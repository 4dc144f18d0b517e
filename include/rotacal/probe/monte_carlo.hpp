// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Monte Carlo check of a touch-probe joint fit's reported 1-sigma (GUM Supplement 1 style), as
/// ballbar/monte_carlo.hpp does for the ballbar: each draw moves every touch of the session along
/// its approach direction to where the identified machine (location errors, sphere, effects)
/// leaves the drawn noise as its residual, refits the draw the same way, and compares the spread
/// of the draws with the reported sigma. The noise is the fit's: AR draws from the noise model
/// when the fit was refitted under it (GLS), else white of the fit's sigma (core/monte_carlo.hpp).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rotacal/core/monte_carlo.hpp"
#include "rotacal/probe/identify.hpp"

namespace rotacal {

struct ProbeMonteCarloOptions {
  int draws = 100;
  std::uint64_t seed = 1;  ///< draw k uses seed + k
  /// How each draw is refitted: the identification's own noise handling (the effects are taken
  /// from the identified model).
  NoiseHandling noise = NoiseHandling::automatic;
  /// Called after every draw with (draws done, draws); may be empty.
  std::function<void(int, int)> progress;
};

struct ProbeMonteCarlo {
  int draws = 0;
  double noise_um = 0.0;                        ///< 1 sigma of the simulated noise per touch
  std::string noise;                            ///< what was simulated, in words
  std::vector<MonteCarloParameter> parameters;  ///< observable parameters only
  Eigen::MatrixXd values;                       ///< draws x all parameters (identification order)
};

/// Throws InvalidArgument if `result` is not a joint fit of `session` (method, machine, touch
/// count) or draws < 2.
ProbeMonteCarlo monte_carlo_probe(const ProbeSession& session, const ProbeIdentification& result,
                                  const ProbeMonteCarloOptions& options = {});

}  // namespace rotacal
