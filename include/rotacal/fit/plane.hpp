// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Total-least-squares plane by SVD of the centred points (Flynn et al. 2016, Eq. 3): the
/// normal is the right singular vector of the smallest singular value; the plane passes
/// through the centroid (Eq. 4).

#include <Eigen/Core>
#include <string>

#include "rotacal/fit/sphere.hpp"

namespace rotacal {

struct PlaneFit {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();          ///< unit; sign: normal . hint >= 0
  Eigen::Vector3d singular_values = Eigen::Vector3d::Zero();  ///< descending
  /// 1-sigma^2 covariance of the normal (3x3, rank 2: it lies in the plane), first order:
  /// sigma^2 * sum_k v_k v_k^T / s_k^2 over the two in-plane singular directions.
  Eigen::Matrix3d normal_covariance = Eigen::Matrix3d::Zero();
  double rms = 0.0;  ///< RMS orthogonal distance
  int n = 0;
};

/// Throws DegenerateGeometry for fewer than 3 points or (nearly) collinear points,
/// InvalidArgument for non-finite input or a zero hint. `sigma` 0: estimated from residuals.
/// `context` (e.g. "s.csv: test axial_C") is put before every error message.
PlaneFit svd_plane_fit(const Eigen::Ref<const Points3>& points,
                       const Eigen::Vector3d& normal_hint = Eigen::Vector3d::UnitZ(),
                       double sigma = 0.0, const std::string& context = "");

}  // namespace rotacal
