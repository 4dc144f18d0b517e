// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/fit/plane.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "rotacal/core/error.hpp"

namespace rotacal {

PlaneFit svd_plane_fit(const Eigen::Ref<const Points3>& p, const Eigen::Vector3d& hint,
                       double sigma, const std::string& context) {
  const std::string who =
      context.empty() ? std::string("svd_plane_fit") : context + ": svd_plane_fit";
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    if (!p.row(i).allFinite())
      throw InvalidArgument(who + ": point " + std::to_string(i) + " of " +
                            std::to_string(p.rows()) + " contains NaN or infinity");
  if (!(hint.norm() > 0.0) || !hint.allFinite())
    throw InvalidArgument(who + ": normal_hint must be non-zero");
  if (p.rows() < 3)
    throw DegenerateGeometry(who + ": " + std::to_string(p.rows()) +
                             " points cannot determine a plane (need 3)");
  PlaneFit f;
  f.n = static_cast<int>(p.rows());
  f.centroid = p.colwise().mean().transpose();
  const Eigen::MatrixXd A = p.rowwise() - f.centroid.transpose();  // Flynn Eq. 3
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinV);
  f.singular_values = svd.singularValues();
  if (!(f.singular_values[1] > 1e-9 * f.singular_values[0]))
    throw DegenerateGeometry(
        who + ": the " + std::to_string(p.rows()) +
        " points are collinear (did the axis move?); the plane through them is undetermined");
  f.normal = svd.matrixV().col(2);
  if (f.normal.dot(hint) < 0) f.normal = -f.normal;
  const double s3 = f.singular_values[2];
  f.rms = s3 / std::sqrt(static_cast<double>(p.rows()));
  const double s2 = sigma > 0 ? sigma * sigma
                              : (p.rows() > 3 ? s3 * s3 / static_cast<double>(p.rows() - 3) : 0.0);
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d v = svd.matrixV().col(k);
    f.normal_covariance += s2 * v * v.transpose() / (f.singular_values[k] * f.singular_values[k]);
  }
  return f;
}

}  // namespace rotacal
