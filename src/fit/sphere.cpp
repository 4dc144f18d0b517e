#include "rotacal/fit/sphere.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <cmath>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

// r = |p - c| - R for one point.
struct SphereDistance {
  explicit SphereDistance(const Eigen::Vector3d& p) : p_(p) {}
  template <typename T>
  bool operator()(const T* centre, const T* radius, T* residual) const {
    const T dx = T(p_.x()) - centre[0], dy = T(p_.y()) - centre[1], dz = T(p_.z()) - centre[2];
    residual[0] = ceres::sqrt(dx * dx + dy * dy + dz * dz) - radius[0];
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& p) {
    return new ceres::AutoDiffCostFunction<SphereDistance, 1, 3, 1>(new SphereDistance(p));
  }
  Eigen::Vector3d p_;
};

}  // namespace

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

  // Geometric refinement.
  ceres::Problem problem;
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    problem.AddResidualBlock(SphereDistance::Create(p.row(i).transpose()), nullptr, centre.data(),
                             &radius);
  if (o.radius) problem.SetParameterBlockConstant(&radius);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.function_tolerance = 1e-15;
  so.parameter_tolerance = 1e-15;
  so.gradient_tolerance = 1e-15;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  SphereFit f;
  f.centre = centre;
  f.radius = radius;
  f.n = static_cast<int>(p.rows());
  f.converged = summary.termination_type == ceres::CONVERGENCE;
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
