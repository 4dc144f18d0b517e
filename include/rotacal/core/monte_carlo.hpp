// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What both instruments' Monte Carlo checks share: the noise of one draw (the fitted noise
/// model's AR streams, or white Gaussian noise) and the comparison of the draws' spread with
/// the reported 1-sigma (GUM Supplement 1 style).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/noise_model.hpp"

namespace rotacal {

struct MonteCarloParameter {
  std::string name;
  std::string unit;
  double std_reported = 0.0;
  double std_mc = 0.0;  ///< sample standard deviation over the draws
  double ratio = 0.0;   ///< std_mc / std_reported (near 1: the reported sigma is right)
  double bias = 0.0;    ///< mean over the draws - identified value
};

/// The noise (mm) of draw k, seeded with std::mt19937_64(seed + k): AR draws per stream from
/// `model` when `coloured`, else `n` white Gaussian values of sigma_um (0: zeros).
Eigen::VectorXd monte_carlo_noise(bool coloured, const NoiseModel& model, double sigma_um,
                                  Eigen::Index n, std::uint64_t seed, int k);

/// One MonteCarloParameter per estimate that is observable and not skipped: the spread of
/// its column of `values` (draws x parameters, estimate order) against its reported sigma.
std::vector<MonteCarloParameter> monte_carlo_summary(
    const std::vector<ParameterEstimate>& estimates, const Eigen::MatrixXd& values,
    const std::function<bool(const ParameterEstimate&)>& skip = {});

}  // namespace rotacal
