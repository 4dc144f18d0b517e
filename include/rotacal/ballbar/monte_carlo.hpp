// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Monte Carlo check of the joint fit's reported 1-sigma (GUM Supplement 1 style): simulate
/// the same poses on the identified machine with the fitted noise, refit each draw the same
/// way, compare the spread with the reported sigma. The draws reuse one prepared problem (the
/// samples' arrays, the identified solution's Jacobian and normal equations: see
/// core/joint_fit.hpp, JointRefitter), so a draw costs a few residual evaluations.

#include <cstdint>
#include <functional>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/monte_carlo.hpp"

namespace rotacal {

struct BallbarMonteCarloOptions {
  int draws = 100;
  std::uint64_t seed = 1;  ///< draw k uses seed + k (as simulate_ballbar with that seed)
  double noise_um = 0.0;   ///< 1 sigma of the simulated noise; 0: the fit's sigma_um
  /// Fit options of the identification being checked (tests, whitener, ...); its effects are
  /// taken from the identified model.
  JointFitOptions fit;
  /// Optional noise model: fills `noise_mm` (one value per fitted sample, session order) for
  /// draw k. Without it: when the identification was refitted under its noise model
  /// (result.noise_refit), AR draws per stream from that model (std::mt19937_64(seed + k))
  /// and each draw refitted under its whitener; else white Gaussian noise of noise_um, drawn
  /// exactly as simulate_ballbar draws it (std::mt19937_64(seed + k), one value per session
  /// sample in order).
  std::function<void(int k, Eigen::Ref<Eigen::VectorXd> noise_mm)> noise;
  /// Called after every draw with (draws done, draws); may be empty.
  std::function<void(int, int)> progress;
};

struct BallbarMonteCarlo {
  int draws = 0;
  double noise_um = 0.0;
  std::string noise;  ///< what was simulated: "white noise", "the fitted noise model: ...", ...
  std::vector<MonteCarloParameter> parameters;  ///< observable parameters only
  Eigen::MatrixXd values;                       ///< draws x all parameters (identification order)
  int fresh_fits = 0;                           ///< draws that needed a fit from scratch
};

/// Throws InvalidArgument if `result` is not a joint fit of `session` (method, machine, sample
/// count), draws < 2, or noise_um < 0.
BallbarMonteCarlo monte_carlo(const BallbarSession& session, const BallbarIdentification& result,
                              const BallbarMonteCarloOptions& options = {});

}  // namespace rotacal
