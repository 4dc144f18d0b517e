// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Monte Carlo check of the R-test joint fit's reported 1-sigma: the identified model's
/// readings (measured - residual, probe zeros included) plus noise drawn from the noise model
/// fitted to the session (AR(1) + random walk per nest and channel by REML, so probe zeros
/// that wander between poses are re-simulated as such; Burg AR(p) with the REML option off)
/// or white noise of the fit's sigma, each draw refitted the way the identification was made
/// (under the same whitener when it was a GLS fit).

#include <cstdint>
#include <functional>

#include "rotacal/core/monte_carlo.hpp"
#include "rotacal/rtest/identify_joint.hpp"

namespace rotacal {

struct RtestMonteCarloOptions {
  int draws = 100;
  std::uint64_t seed = 1;  ///< draw k uses std::mt19937_64(seed + k)
  RtestJointOptions
      fit;  ///< the identification's options (basis); noise handling is taken from the result
  /// Called after every draw with (draws done, draws); may be empty.
  std::function<void(int, int)> progress;
};

struct RtestMonteCarlo {
  int draws = 0;
  std::string noise;                            ///< what was simulated
  std::vector<MonteCarloParameter> parameters;  ///< observable location errors and map coefficients
  Eigen::MatrixXd values;                       ///< draws x all parameters
};

/// Throws InvalidArgument if `result` is not a joint fit of `session` (sample count) or
/// draws < 2.
RtestMonteCarlo monte_carlo(const RtestSession& session, const RtestJointIdentification& result,
                            const RtestMonteCarloOptions& options = {});

}  // namespace rotacal
