// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Least-squares sphere: algebraic start, geometric (orthogonal distance) refinement (Ceres'
/// solver, or rotacal's joint-fit driver with -DROTACAL_CERES_SOLVER=OFF). Flynn et al. (2016,
/// Sec. 3.1) locate the ballbar's centre pivot this way from the three arcs at rotary zero; with
/// the calibrated bar length as a fixed radius, because a free radius confounds the pivot height
/// with the radius on the short YZ and ZX arcs.

#include <Eigen/Core>
#include <optional>

namespace rotacal {

using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct SphereFit {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
  /// 1-sigma^2 covariance of (centre x, y, z, radius); the radius row/column is zero when the
  /// radius was fixed.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  double rms = 0.0;  ///< RMS orthogonal distance
  int n = 0;
  bool converged = false;
};

struct SphereFitOptions {
  std::optional<double> radius;  ///< fix the radius (e.g. the calibrated ballbar length)
  double sigma = 0.0;            ///< known 1-sigma noise; 0: estimate from the residuals
  /// Refuse (DegenerateGeometry) a solution whose Jacobian's condition number exceeds this:
  /// points degenerate only to within their noise (one spot, one great circle, one plane).
  /// 0: no such check.
  double max_condition = 0.0;
};

/// Throws DegenerateGeometry for too few points (4 free radius, 3 fixed), collinear points,
/// coplanar points (a free radius is then undetermined; a fixed one has two mirror
/// solutions), or a condition number beyond options.max_condition; InvalidArgument for non-finite
/// input or a radius <= 0.
SphereFit sphere_fit(const Eigen::Ref<const Points3>& points, const SphereFitOptions& options = {});

}  // namespace rotacal
