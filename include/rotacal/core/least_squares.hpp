// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What every joint fit reports once it has converged: which parameter combinations the data
/// cannot see (eigen-decomposition of the scaled normal matrix), and the 1-sigma covariance of
/// the parameters that it can see. The driver that calls them is core/joint_fit.hpp.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rotacal {

/// J^T J of a tall matrix (rows >> columns), by one matrix-vector product per column, the lower
/// triangle mirrored. Measured against Eigen's rankUpdate (a blocked, packed product) on this
/// project's shapes: 1,804 x 11 17 us instead of 34-46 us, 3,000 x 60 0.83 ms instead of 1.13,
/// 20,000 x 40 2.7 ms instead of 3.3, 600,000 x 11 15.3 ms instead of 15.8.
Eigen::MatrixXd gram_matrix(const Eigen::Ref<const Eigen::MatrixXd>& J);

/// Which parameter combinations the data cannot determine. J is weighted (residuals in units
/// of their sigma); `scales` holds a plausible magnitude of each parameter (e.g. 1 mm, 1 mrad).
/// A direction is unobservable when moving along it by those magnitudes changes chi-square by
/// less than `min_chi2_change`: singular value of J*diag(scales) below its square root.
struct Observability {
  /// Per parameter: its share in the null space (norm of its row in an orthonormal basis of it,
  /// scaled) is at most 0.05, and it is not held. Independent of the basis of the null space.
  std::vector<bool> observable;
  /// Directions in parameter space (original units); direction k moves to_fix[k] and no other
  /// held parameter.
  std::vector<Eigen::VectorXd> null_space;
  Eigen::VectorXd singular_values;  ///< of J*diag(scales), descending
  /// Parameters to hold fixed so that the rest is determined: one per null direction, all
  /// distinct, chosen by largest remaining (scaled) share in the null space (pivoted QR).
  std::vector<int> to_fix;
  /// Null direction k in words, e.g. "E_X0C +1 mm with E_B0C +0.0167 rad changes no reading".
  std::string describe(int k, const std::vector<std::string>& names,
                       const std::vector<std::string>& units) const;
};
Observability analyse_observability(const Eigen::MatrixXd& J, const Eigen::VectorXd& scales,
                                    double min_chi2_change = 1.0);
/// The same from the normal matrix J^T J (p x p), so that a fit over 10^6 residuals need not
/// copy its Jacobian: the singular values of J*diag(scales) are the square roots of the
/// eigenvalues of diag(scales) J^T J diag(scales).
Observability analyse_observability_normal(const Eigen::MatrixXd& JtJ,
                                           const Eigen::VectorXd& scales,
                                           double min_chi2_change = 1.0);

/// Plausible magnitude of a parameter by its unit, for analyse_observability: 1 mm, 1 mrad,
/// 1 um/s, 1e-3 for ratios (rad/rad, mm/mm), 1 ms for a time (s, a servo lag), 1 for a
/// dimensionless "1" (e.g. a log time constant).
/// Throws InvalidArgument for an unknown unit.
double plausible_magnitude(const std::string& unit);

/// 1-sigma covariance (J^T J)^-1 * sigma2 restricted to the parameters in `free` (others get
/// zero rows/columns), computed by SVD of the column-normalised Jacobian for conditioning.
Eigen::MatrixXd covariance_from_jacobian(const Eigen::MatrixXd& J, const std::vector<bool>& free,
                                         double sigma2);

}  // namespace rotacal
