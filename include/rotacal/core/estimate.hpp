// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What every fit reports, whatever the instrument: one estimate per parameter (value, 1 sigma,
/// unit, observable) and a summary of the solve (convergence, chi-square per degree of freedom).

#include <cstddef>
#include <string>

namespace rotacal {

/// One identified quantity. `observable == false` means the data cannot determine it: value
/// and std are then meaningless and are not reported by the writers.
struct ParameterEstimate {
  std::string name;
  double value = 0.0;
  double std = 0.0;  ///< 1 sigma
  std::string unit;
  bool observable = true;
};

/// How a least-squares solve went (core/joint_fit.hpp).
struct FitSummary {
  bool converged = false;
  int iterations = 0;  ///< accepted steps
  int jacobian_evaluations = 0;
  int residual_evaluations = 0;
  std::size_t num_residuals = 0;
  int num_free = 0;  ///< parameters estimated (not held)
  /// Sum of squared weighted residuals: in units of the declared sigma without a whitener,
  /// of the whitened residuals (units of their own sigma) with one.
  double chi2 = 0.0;
  double chi2_per_dof = 0.0;  ///< chi2 / (num_residuals - num_free)
  bool whitened = false;      ///< a ResidualWhitener was applied (GLS)
  std::string message;        ///< why the solver stopped, in words
};

}  // namespace rotacal
