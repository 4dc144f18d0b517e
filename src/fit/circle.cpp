// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/fit/circle.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "orthogonal_distance.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

std::string with_context(const CircleFitOptions& o, const char* fit) {
  return o.context.empty() ? std::string(fit) : o.context + ": " + fit;
}

Eigen::Index non_finite_row(const Eigen::Ref<const Points2>& p) {
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    if (!p.row(i).allFinite()) return i;
  return -1;
}

void check_points(const Eigen::Ref<const Points2>& p, const std::string& who) {
  if (!p.allFinite())
    throw InvalidArgument(who + ": point " + std::to_string(non_finite_row(p)) + " of " +
                          std::to_string(p.rows()) + " contains NaN or infinity");
  if (p.rows() < 3)
    throw DegenerateGeometry(who + ": " + std::to_string(p.rows()) +
                             " points cannot determine a circle (need 3 or more)");
  const Eigen::RowVector2d mean = p.colwise().mean();
  const Eigen::MatrixXd c = p.rowwise() - mean;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(c);
  const auto s = svd.singularValues();
  if (!(s[1] > 1e-9 * s[0]))
    throw DegenerateGeometry(
        who + ": the " + std::to_string(p.rows()) +
        " points are collinear (did the axis move?); no circle passes through them");
}

// Orthogonal residuals, covariance from their Jacobian, and the short-arc check.
CircleFit finish(const Eigen::Ref<const Points2>& p, Eigen::Vector2d centre, double radius,
                 const CircleFitOptions& o, const std::string& who) {
  // The geometric refinement (orthogonal_distance.hpp; Ceres examples/circle_fit.cc without its
  // reparameterisation: the radius here is at least one sagitta away from zero).
  if (o.refine) refine_orthogonal_distance<2>(p, centre, radius, false);
  CircleFit f;
  f.centre = centre;
  f.radius = radius;
  f.n = static_cast<int>(p.rows());
  Eigen::MatrixXd J(p.rows(), 3);
  double ss = 0.0;
  double lo = M_PI, hi = -M_PI;
  std::vector<double> angles;
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const Eigen::Vector2d d = p.row(i).transpose() - centre;
    const double dist = d.norm();
    ss += (dist - radius) * (dist - radius);
    J.row(i) << -d.x() / dist, -d.y() / dist, -1.0;
    angles.push_back(std::atan2(d.y(), d.x()));
    lo = std::min(lo, angles.back()), hi = std::max(hi, angles.back());
  }
  f.rms = std::sqrt(ss / static_cast<double>(p.rows()));
  // Angular extent of the arc: 2 pi minus the largest gap between neighbouring points.
  std::sort(angles.begin(), angles.end());
  double gap = angles.front() + 2 * M_PI - angles.back();
  for (std::size_t k = 1; k < angles.size(); ++k) gap = std::max(gap, angles[k] - angles[k - 1]);
  const double span = 2 * M_PI - gap;
  const double sagitta = radius * (1.0 - std::cos(std::min(span, M_PI) / 2.0));
  const double scatter = p.rows() > 3 ? std::sqrt(ss / static_cast<double>(p.rows() - 3)) : 0.0;
  if (sagitta < o.min_sagitta_ratio * scatter)
    throw DegenerateGeometry(who + ": the arc is too short to fit: its sagitta " +
                             std::to_string(sagitta) + " is below " +
                             std::to_string(o.min_sagitta_ratio) + " x the scatter " +
                             std::to_string(scatter));
  const double s2 = o.sigma > 0 ? o.sigma * o.sigma
                                : (p.rows() > 3 ? ss / static_cast<double>(p.rows() - 3) : 0.0);
  f.covariance = (J.transpose() * J).inverse() * s2;
  return f;
}

}  // namespace

CircleFit hyper_circle_fit(const Eigen::Ref<const Points2>& p, const CircleFitOptions& o) {
  const std::string who = with_context(o, "hyper_circle_fit");
  check_points(p, who);
  // Moments of the centred data (Al-Sharadqah & Chernov 2009; Chernov's reference "Hyper"
  // algorithm, solved by Newton's method on the characteristic polynomial).
  const Eigen::RowVector2d mean = p.colwise().mean();
  double Mxx = 0, Myy = 0, Mxy = 0, Mxz = 0, Myz = 0, Mzz = 0;
  const double n = static_cast<double>(p.rows());
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const double x = p(i, 0) - mean.x(), y = p(i, 1) - mean.y(), z = x * x + y * y;
    Mxx += x * x, Myy += y * y, Mxy += x * y, Mxz += x * z, Myz += y * z, Mzz += z * z;
  }
  Mxx /= n, Myy /= n, Mxy /= n, Mxz /= n, Myz /= n, Mzz /= n;
  const double Mz = Mxx + Myy, Cov_xy = Mxx * Myy - Mxy * Mxy, Var_z = Mzz - Mz * Mz;
  const double A2 = 4 * Cov_xy - 3 * Mz * Mz - Mzz;
  const double A1 = Var_z * Mz + 4 * Cov_xy * Mz - Mxz * Mxz - Myz * Myz;
  const double A0 = Mxz * (Mxz * Myy - Myz * Mxy) + Myz * (Myz * Mxx - Mxz * Mxy) - Var_z * Cov_xy;
  double x = 0.0, y = A0;
  for (int it = 0; it < 99; ++it) {
    const double Dy = A1 + x * (2 * A2 + 16 * x * x);
    const double xnew = x - y / Dy;
    if (xnew == x || !std::isfinite(xnew)) break;
    const double ynew = A0 + xnew * (A1 + xnew * (A2 + 4 * xnew * xnew));
    if (std::abs(ynew) >= std::abs(y)) break;
    x = xnew, y = ynew;
  }
  const double det = x * x - x * Mz + Cov_xy;
  const double cx = (Mxz * (Myy - x) - Myz * Mxy) / det / 2.0;
  const double cy = (Myz * (Mxx - x) - Mxz * Mxy) / det / 2.0;
  const double r = std::sqrt(cx * cx + cy * cy + Mz - 2 * x);
  if (!std::isfinite(r))
    throw DegenerateGeometry(who + ": no circle fits these " + std::to_string(p.rows()) +
                             " points");
  return finish(p, Eigen::Vector2d(cx + mean.x(), cy + mean.y()), r, o, who);
}

CircleFit kasa_circle_fit(const Eigen::Ref<const Points2>& p, const CircleFitOptions& o) {
  const std::string who = with_context(o, "kasa_circle_fit");
  check_points(p, who);
  const Eigen::RowVector2d mean = p.colwise().mean();
  Eigen::MatrixXd A(p.rows(), 3);
  Eigen::VectorXd b(p.rows());
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const double x = p(i, 0) - mean.x(), y = p(i, 1) - mean.y();
    A.row(i) << x, y, 1.0;
    b[i] = -(x * x + y * y);
  }
  const Eigen::Vector3d s = A.colPivHouseholderQr().solve(b);  // x^2+y^2 + D x + E y + F = 0
  const Eigen::Vector2d c(-s[0] / 2, -s[1] / 2);
  const double r = std::sqrt(c.squaredNorm() - s[2]);
  if (!std::isfinite(r))
    throw DegenerateGeometry(who + ": no circle fits these " + std::to_string(p.rows()) +
                             " points");
  return finish(p, c + mean.transpose(), r, o, who);
}

}  // namespace rotacal
