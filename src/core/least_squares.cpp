// SPDX-License-Identifier: BSD-3-Clause
// Observability and covariance of least-squares fits (no solver here: core/joint_fit.cpp).
#include "rotacal/core/least_squares.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <sstream>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {
Eigen::VectorXd column_scales(const Eigen::MatrixXd& J) {
  Eigen::VectorXd s = J.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < s.size(); ++j)
    if (!(s[j] > 0.0)) s[j] = 1.0;  // a column of zeros: the parameter does nothing
  return s;
}
}  // namespace

Eigen::MatrixXd gram_matrix(const Eigen::Ref<const Eigen::MatrixXd>& J) {
  const Eigen::Index p = J.cols();
  Eigen::MatrixXd G(p, p);
  for (Eigen::Index a = 0; a < p; ++a) {
    G.col(a).tail(p - a).noalias() = J.rightCols(p - a).transpose() * J.col(a);
    G.row(a).tail(p - a) = G.col(a).tail(p - a).transpose();
  }
  return G;
}

Observability analyse_observability(const Eigen::MatrixXd& J, const Eigen::VectorXd& scales,
                                    double min_chi2_change) {
  if (scales.size() != J.cols())
    throw InvalidArgument("analyse_observability: scales has " + std::to_string(scales.size()) +
                          " entries for " + std::to_string(J.cols()) + " parameters");
  // A non-finite Jacobian (readings far beyond any machine) would reach the eigensolver as
  // NaN; the readers refuse such values, and this stops any other path to it.
  if (!J.allFinite())
    throw InvalidArgument(
        "analyse_observability: the Jacobian is not finite (a reading or parameter is out of "
        "range)");
  return analyse_observability_normal(gram_matrix(J), scales, min_chi2_change);
}

Observability analyse_observability_normal(const Eigen::MatrixXd& JtJ,
                                           const Eigen::VectorXd& scales, double min_chi2_change) {
  const Eigen::Index p = JtJ.cols();
  if (scales.size() != p || JtJ.rows() != p)
    throw InvalidArgument("analyse_observability: scales has " + std::to_string(scales.size()) +
                          " entries for " + std::to_string(p) + " parameters");
  Observability o;
  o.observable.assign(static_cast<std::size_t>(p), true);
  if (p == 0) return o;
  if (!JtJ.allFinite())
    throw InvalidArgument(
        "analyse_observability: the normal matrix is not finite (a reading or parameter is out of "
        "range)");
  // Eigenvalues of the scaled normal matrix are the squared singular values of J*diag(scales);
  // their absolute error (~1e-16 of the largest) is far below the threshold of ~1 (chi2 units).
  const Eigen::MatrixXd N = scales.asDiagonal() * JtJ * scales.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(N);
  o.singular_values.resize(p);
  Eigen::MatrixXd V(p, p);
  for (Eigen::Index k = 0; k < p; ++k) {  // descending, as an SVD orders them
    o.singular_values[k] = std::sqrt(std::max(0.0, es.eigenvalues()[p - 1 - k]));
    V.col(k) = es.eigenvectors().col(p - 1 - k);
  }
  const double limit = std::sqrt(min_chi2_change);
  Eigen::Index k_null = 0;
  while (k_null < p && o.singular_values[p - 1 - k_null] < limit) ++k_null;
  if (k_null == 0) return o;
  // The null space as one subspace: when several directions are below the limit (a session
  // that lacks whole poses, e.g. a tilt polynomial of degree 6 over four B angles), their
  // eigenvalues are (nearly) equal and the eigensolver's basis of that subspace is arbitrary.
  // So nothing below may depend on that basis. Parameter j takes part in the null space when
  // its share in it, the norm of row j of the orthonormal basis, is above 0.05; judged per basis
  // vector instead, a parameter could have a share under 0.05 in each of several directions
  // and still be free to move, and be reported determined.
  const Eigen::MatrixXd Vn = V.rightCols(k_null);  // ascending singular values: the null space
  for (Eigen::Index j = 0; j < p; ++j)
    if (Vn.row(j).norm() > 0.05) o.observable[static_cast<std::size_t>(j)] = false;
  // Parameters to hold: greedy column-pivoted QR of Vn^T, which picks k_null distinct
  // parameters whose rows span the null space, so that holding them leaves the rest
  // determined. (One per direction, each the largest share of its own direction, could pick
  // the same parameter twice: the free set was then still singular and its covariance
  // meaningless, e.g. a parameter reported with a 1-sigma of exactly 0.) The residual row
  // norms are independent of the basis of the subspace. Equal shares (e.g. a head's tool
  // length, its axis' position along the spindle and the pivot height, 1/sqrt(3) each) would
  // leave the choice to rounding: hold the last of them, the parameter a model adds on top of
  // the base ones, so that repeated fits agree.
  Eigen::MatrixXd R = Vn;
  std::vector<bool> taken(static_cast<std::size_t>(p), false);
  for (Eigen::Index k = 0; k < k_null; ++k) {
    int best = -1;
    for (Eigen::Index j = 0; j < p; ++j)
      if (!taken[static_cast<std::size_t>(j)] && (best < 0 || R.row(j).norm() > R.row(best).norm()))
        best = static_cast<int>(j);
    for (Eigen::Index j = p - 1; j > best; --j)
      if (!taken[static_cast<std::size_t>(j)] &&
          R.row(j).norm() >= (1.0 - 1e-3) * R.row(best).norm()) {
        best = static_cast<int>(j);
        break;
      }
    taken[static_cast<std::size_t>(best)] = true;
    o.to_fix.push_back(best);
    // A held parameter is not determined by the data, whatever its share.
    o.observable[static_cast<std::size_t>(best)] = false;
    const Eigen::RowVectorXd u = R.row(best) / R.row(best).norm();
    R -= (R * u.transpose()) * u;
  }
  // The directions reported, in a basis fixed by the held parameters: direction k moves held
  // parameter k alone among them (reduced echelon form of the null space), so that repeated
  // fits describe them alike.
  Eigen::MatrixXd F(k_null, k_null);
  for (Eigen::Index k = 0; k < k_null; ++k)
    F.row(k) = Vn.row(o.to_fix[static_cast<std::size_t>(k)]);
  const Eigen::MatrixXd E = Vn * F.inverse();
  for (Eigen::Index k = 0; k < k_null; ++k) {
    const Eigen::VectorXd vs = E.col(k).normalized();
    o.null_space.push_back(vs.cwiseProduct(scales));
  }
  return o;
}

double plausible_magnitude(const std::string& unit) {
  if (unit == "mm") return 1.0;
  if (unit == "rad") return 1e-3;
  if (unit == "mm/s") return 1e-3;
  if (unit == "rad/rad" || unit == "mm/mm") return 1e-3;
  if (unit == "s") return 1e-3;  // a servo lag: 1 ms is a gain mismatch of a few percent
  if (unit == "1") return 1.0;   // dimensionless, e.g. the log of a time constant: a factor e
  throw InvalidArgument("plausible_magnitude: unknown unit '" + unit + "'");
}

std::string Observability::describe(int k, const std::vector<std::string>& names,
                                    const std::vector<std::string>& units) const {
  const Eigen::VectorXd& v = null_space.at(static_cast<std::size_t>(k));
  // Lead with the parameter that has the largest share relative to its plausible size.
  int lead = 0;
  double lead_share = -1.0;
  for (Eigen::Index j = 0; j < v.size(); ++j) {
    const double share =
        std::abs(v[j]) / plausible_magnitude(units.at(static_cast<std::size_t>(j)));
    if (share > lead_share) lead = static_cast<int>(j), lead_share = share;
  }
  const double unit_step = plausible_magnitude(units.at(static_cast<std::size_t>(lead)));
  std::ostringstream out;
  out.precision(3);
  out << names.at(static_cast<std::size_t>(lead)) << " +" << unit_step << " "
      << units[static_cast<std::size_t>(lead)];
  for (Eigen::Index j = 0; j < v.size(); ++j) {
    if (j == lead) continue;
    const double step = v[j] / v[lead] * unit_step;
    if (std::abs(step) < 0.05 * plausible_magnitude(units[static_cast<std::size_t>(j)])) continue;
    out << " with " << names[static_cast<std::size_t>(j)] << " " << (step < 0 ? "" : "+") << step
        << " " << units[static_cast<std::size_t>(j)];
  }
  out << " changes no reading measurably";
  return out.str();
}

Eigen::MatrixXd covariance_from_jacobian(const Eigen::MatrixXd& J, const std::vector<bool>& free,
                                         double sigma2) {
  const Eigen::Index p = J.cols();
  ROTACAL_ASSERT(static_cast<Eigen::Index>(free.size()) == p);
  std::vector<Eigen::Index> idx;
  for (Eigen::Index j = 0; j < p; ++j)
    if (free[static_cast<std::size_t>(j)]) idx.push_back(j);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(p, p);
  if (idx.empty()) return cov;
  Eigen::MatrixXd Jf(J.rows(), static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k) Jf.col(static_cast<Eigen::Index>(k)) = J.col(idx[k]);
  const Eigen::VectorXd s = column_scales(Jf);
  const Eigen::MatrixXd Jn = Jf * s.cwiseInverse().asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jn, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(sv.size());
  for (Eigen::Index k = 0; k < sv.size(); ++k)
    if (sv[k] > 1e-12 * sv[0]) inv2[k] = 1.0 / (sv[k] * sv[k]);
  const Eigen::MatrixXd Cn = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
  const Eigen::MatrixXd Cf =
      s.cwiseInverse().asDiagonal() * Cn * s.cwiseInverse().asDiagonal() * sigma2;
  for (std::size_t a = 0; a < idx.size(); ++a)
    for (std::size_t b = 0; b < idx.size(); ++b)
      cov(idx[a], idx[b]) = Cf(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  return cov;
}

}  // namespace rotacal
