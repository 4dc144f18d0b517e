// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Linear least squares with each unknown held within its bound: min_s sum_i w_i (d_i - (R s)_i)^2
/// subject to |s_j| <= bounds_j, by cyclic coordinate descent (the problem is convex, so the
/// descent reaches its minimum; each coordinate's step is the exact minimum along it, clipped to
/// its bound). Sized for a few unknowns and a few residuals, called many times (the greedy model
/// extension of the Table 2 analysis, python/rotacal/flynn_table2/scenario.py).

#include <Eigen/Core>

namespace rotacal {

struct BoxLeastSquaresOptions {
  int max_sweeps = 200;     ///< passes over every unknown
  double tolerance = 1e-9;  ///< stop when no unknown moves by more than this fraction of its bound
};

/// The solution s (R.cols() values). A column with no weight on it (sum w r^2 = 0) stays at
/// zero. Throws InvalidArgument for mismatched sizes, non-finite values, a negative weight or
/// a negative bound.
Eigen::VectorXd box_least_squares(const Eigen::MatrixXd& R, const Eigen::VectorXd& d,
                                  const Eigen::VectorXd& w, const Eigen::VectorXd& bounds,
                                  const BoxLeastSquaresOptions& options = {});

}  // namespace rotacal
