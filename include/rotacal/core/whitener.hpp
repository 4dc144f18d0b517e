// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The seam between a noise model and the joint fits: a linear map W applied to residuals and
/// Jacobian columns, so that a fit minimises |W r|^2 (generalised least squares). With W the
/// inverse Cholesky factor of the noise covariance, the whitened residuals are independent
/// with unit variance, and (J^T W^T W J)^-1 is the parameters' covariance even when the noise
/// is correlated. core/noise_model.hpp implements it; null means white noise.

#include <Eigen/Core>

namespace rotacal {

class ResidualWhitener {
 public:
  virtual ~ResidualWhitener() = default;
  /// Replace each column c (one value per residual, in the fit's residual order) by W c, in
  /// place. Called on the residual vector and on every Jacobian column alike, so W must be
  /// linear and must not depend on the column.
  virtual void apply(Eigen::Ref<Eigen::MatrixXd> columns) const = 0;
  /// Number of residuals the whitener was built for (the fit checks it against its own).
  virtual Eigen::Index size() const = 0;
};

}  // namespace rotacal
