// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Circle fits to 2-D points: the "Hyper" algebraic fit of Al-Sharadqah & Chernov (2009),
/// which Flynn et al. (2016, Sec. 3.2) use for the centre of rotation, the plain Kasa fit it
/// improves on, and a geometric (orthogonal distance) refinement (Ceres' solver, or rotacal's
/// joint-fit driver in a build with -DROTACAL_CERES_SOLVER=OFF).

#include <Eigen/Core>
#include <string>

namespace rotacal {

using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

struct CircleFit {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius = 0.0;
  /// 1-sigma^2 covariance of (centre x, centre y, radius), from the geometric Jacobian with
  /// sigma^2 = sum of squared orthogonal residuals / (n - 3) unless a sigma was given.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double rms = 0.0;  ///< RMS orthogonal distance of the points to the circle
  int n = 0;
};

struct CircleFitOptions {
  double sigma = 0.0;              ///< known 1-sigma noise of the points (same units); 0: estimate
  bool refine = false;             ///< polish the algebraic solution by orthogonal distances
  double min_sagitta_ratio = 3.0;  ///< refuse arcs whose sagitta is below this x the scatter
  /// What the points are, put before every error message (e.g. "s.csv: test radial_A"), so a
  /// refusal names the data rather than only the fit.
  std::string context;
};

/// Hyper fit (Al-Sharadqah & Chernov 2009, Sec. 7): the algebraic fit whose essential bias
/// vanishes to second order. Throws DegenerateGeometry for fewer than 3 points, collinear
/// points or an arc too short to fit (sagitta below min_sagitta_ratio x the scatter), and
/// InvalidArgument for non-finite input.
CircleFit hyper_circle_fit(const Eigen::Ref<const Points2>& points,
                           const CircleFitOptions& options = {});

/// Kasa fit: least squares of x^2 + y^2 + D x + E y + F = 0. Biased towards smaller radii on
/// short noisy arcs; kept for comparison. Same errors as hyper_circle_fit.
CircleFit kasa_circle_fit(const Eigen::Ref<const Points2>& points,
                          const CircleFitOptions& options = {});

}  // namespace rotacal
