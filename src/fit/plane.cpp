#include "rotacal/fit/plane.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "rotacal/core/error.hpp"

namespace rotacal {

PlaneFit svd_plane_fit(const Eigen::Ref<const Points3>& p, const Eigen::Vector3d& hint, double sigma) {
  if (!p.allFinite()) throw InvalidArgument("svd_plane_fit: points contain NaN or infinity");
  if (!(hint.norm() > 0.0) || !hint.allFinite()) throw InvalidArgument("svd_plane_fit: normal_hint must be non-zero");
  if (p.rows() < 3)
    throw DegenerateGeometry("svd_plane_fit: " + std::to_string(p.rows()) + " points cannot determine a plane");
  PlaneFit f;
  f.n = static_cast<int>(p.rows());
  f.centroid = p.colwise().mean().transpose();
  const Eigen::MatrixXd A = p.rowwise() - f.centroid.transpose();  // Flynn Eq. 3
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinV);
  f.singular_values = svd.singularValues();
  if (!(f.singular_values[1] > 1e-9 * f.singular_values[0]))
    throw DegenerateGeometry("svd_plane_fit: the points are collinear; the plane through them is undetermined");
  f.normal = svd.matrixV().col(2);
  if (f.normal.dot(hint) < 0) f.normal = -f.normal;
  const double s3 = f.singular_values[2];
  f.rms = s3 / std::sqrt(static_cast<double>(p.rows()));
  const double s2 = sigma > 0 ? sigma * sigma : (p.rows() > 3 ? s3 * s3 / static_cast<double>(p.rows() - 3) : 0.0);
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d v = svd.matrixV().col(k);
    f.normal_covariance += s2 * v * v.transpose() / (f.singular_values[k] * f.singular_values[k]);
  }
  return f;
}

}  // namespace rotacal
