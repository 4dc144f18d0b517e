// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/fit/sphere.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "orthogonal_distance.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

SphereFit sphere_fit(const Eigen::Ref<const Points3>& p, const SphereFitOptions& o) {
  if (!p.allFinite()) throw InvalidArgument("sphere_fit: points contain NaN or infinity");
  if (o.radius && !(*o.radius > 0.0 && std::isfinite(*o.radius)))
    throw InvalidArgument("sphere_fit: radius must be finite and > 0");
  const int need = o.radius ? 3 : 4;
  if (p.rows() < need)
    throw DegenerateGeometry("sphere_fit: " + std::to_string(p.rows()) +
                             " points cannot determine a sphere (need " + std::to_string(need) +
                             " or more)");
  const Eigen::RowVector3d mean = p.colwise().mean();
  const Eigen::MatrixXd c = p.rowwise() - mean;
  Eigen::JacobiSVD<Eigen::MatrixXd> shape(c);
  const Eigen::Vector3d s = shape.singularValues();
  if (!(s[1] > 1e-9 * s[0])) throw DegenerateGeometry("sphere_fit: the points are collinear");
  if (!(s[2] > 1e-6 * s[0]))
    throw DegenerateGeometry(
        o.radius ? "sphere_fit: the points are coplanar; with a fixed radius the centre "
                   "has two mirror solutions, one each side of their plane"
                 : "sphere_fit: the points are coplanar; a free radius is undetermined");

  // Algebraic start: |p|^2 + D.p + G = 0 (centre -D/2), on centred coordinates.
  Eigen::MatrixXd A(p.rows(), 4);
  Eigen::VectorXd b(p.rows());
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    A.row(i) << c(i, 0), c(i, 1), c(i, 2), 1.0;
    b[i] = -c.row(i).squaredNorm();
  }
  const Eigen::Vector4d sol = A.colPivHouseholderQr().solve(b);
  Eigen::Vector3d centre = -sol.head<3>() / 2.0;
  double radius = std::sqrt(centre.squaredNorm() - sol[3]);
  centre += mean.transpose();
  if (o.radius) radius = *o.radius;

  // Geometric refinement (orthogonal_distance.hpp).
  const bool converged = refine_orthogonal_distance<3>(p, centre, radius, o.radius.has_value());

  SphereFit f;
  f.centre = centre;
  f.radius = radius;
  f.n = static_cast<int>(p.rows());
  f.converged = converged;
  const int k = o.radius ? 3 : 4;
  Eigen::MatrixXd J(p.rows(), k);
  double ss = 0.0;
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const Eigen::Vector3d d = p.row(i).transpose() - centre;
    const double dist = d.norm();
    ss += (dist - radius) * (dist - radius);
    J.block(i, 0, 1, 3) = -d.transpose() / dist;
    if (!o.radius) J(i, 3) = -1.0;
  }
  f.rms = std::sqrt(ss / static_cast<double>(p.rows()));
  if (o.max_condition > 0.0) {
    // Points on one great circle, in one plane (radius free) or at one spot only to within
    // their noise pass the shape checks above, yet leave a direction of the solution resting on
    // the noise: the Jacobian's condition number shows it whatever the scale.
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(J).singularValues();
    const double cond = sv[0] / sv[sv.size() - 1];
    if (!(cond <= o.max_condition))
      throw DegenerateGeometry(
          "sphere_fit: the points leave the " +
          std::string(o.radius ? "centre" : "centre and radius") +
          " undetermined in one direction (condition number " + std::to_string(cond) +
          ", more than " + std::to_string(o.max_condition) + "): they lie, to within their " +
          "noise, " +
          (o.radius ? "on one great circle or at one spot (need 3 off one great circle)"
                    : "in one plane or at one spot (need 4 off one plane)"));
  }
  const double s2 = o.sigma > 0 ? o.sigma * o.sigma
                                : (p.rows() > k ? ss / static_cast<double>(p.rows() - k) : 0.0);
  f.covariance.topLeftCorner(k, k) = (J.transpose() * J).inverse() * s2;
  return f;
}

}  // namespace rotacal
