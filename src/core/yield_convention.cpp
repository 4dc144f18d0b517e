// SPDX-License-Identifier: BSD-3-Clause
// The yield convention for effects that share directions with the baseline (yield_convention.hpp).
#include "rotacal/core/yield_convention.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <vector>

#include "rotacal/core/error.hpp"

namespace rotacal {

Eigen::MatrixXd yield_convention(const Observability& o, const std::vector<bool>& yields,
                                 const Eigen::VectorXd& scales, std::vector<bool>* observable) {
  const Eigen::Index m = scales.size();
  const Eigen::Index k = static_cast<Eigen::Index>(o.null_space.size());
  ROTACAL_ASSERT(static_cast<Eigen::Index>(yields.size()) == m);
  if (k == 0) return {};
  std::vector<Eigen::Index> y;
  for (Eigen::Index j = 0; j < m; ++j)
    if (yields[static_cast<std::size_t>(j)]) y.push_back(j);
  if (y.empty()) return {};
  // Orthonormal basis Q of the null space in scaled units (z = x / scale).
  Eigen::MatrixXd Ns(m, k);
  for (Eigen::Index c = 0; c < k; ++c)
    Ns.col(c) = o.null_space[static_cast<std::size_t>(c)].cwiseQuotient(scales);
  const Eigen::MatrixXd Q = Ns.householderQr().householderQ() * Eigen::MatrixXd::Identity(m, k);
  // Its yielding part, and the directions in which that part is not negligible.
  Eigen::MatrixXd A(static_cast<Eigen::Index>(y.size()), k);
  for (std::size_t r = 0; r < y.size(); ++r) A.row(static_cast<Eigen::Index>(r)) = Q.row(y[r]);
  // The SVD splits the null space into orthonormal directions whose yielding parts (norms
  // sv[i]) and other parts (norms sqrt(1 - sv[i]^2)) are each orthogonal. A direction is a
  // trade-off between an effect and the baseline, which the convention resolves, only when it
  // has both; one inside the effects alone (a radial motion's component the bar cannot see)
  // or inside the baseline alone stays unobservable.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  // Both parts at least 0.3 of the direction: a trade-off that mostly moves an effect, with the
  // baseline's part a matter of a few percent, is that effect's invisible component.
  const double share = 0.3, pure = std::sqrt(1.0 - share * share);
  std::vector<Eigen::Index> resolved, left;
  for (Eigen::Index i = 0; i < k; ++i)
    ((i < sv.size() && sv[i] > share && sv[i] < pure) ? resolved : left).push_back(i);
  if (resolved.empty()) return {};
  const Eigen::Index g = static_cast<Eigen::Index>(resolved.size());
  Eigen::MatrixXd Vg(k, g), Vr(k, static_cast<Eigen::Index>(left.size()));
  for (Eigen::Index i = 0; i < g; ++i)
    Vg.col(i) = svd.matrixV().col(resolved[static_cast<std::size_t>(i)]);
  for (Eigen::Index i = 0; i < Vr.cols(); ++i)
    Vr.col(i) = svd.matrixV().col(left[static_cast<std::size_t>(i)]);
  const Eigen::MatrixXd Qg = Q * Vg;  // resolved directions
  const Eigen::MatrixXd Qr = Q * Vr;  // left as they are
  const Eigen::MatrixXd Ag = A * Vg;
  // z' = z + Qg t with Ag^T (z'_y) = 0: t = -(Ag^T Ag)^-1 Ag^T z_y. In scaled units
  // Mz = I - Qg (Ag^T Ag)^-1 Ag^T E_y; in the parameters' own units M = S Mz S^-1.
  Eigen::MatrixXd Ey = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(y.size()), m);
  for (std::size_t r = 0; r < y.size(); ++r) Ey(static_cast<Eigen::Index>(r), y[r]) = 1.0;
  const Eigen::MatrixXd T = (Ag.transpose() * Ag).ldlt().solve(Ag.transpose() * Ey);
  Eigen::MatrixXd Mz = Eigen::MatrixXd::Identity(m, m) - Qg * T;
  const Eigen::MatrixXd M = scales.asDiagonal() * Mz * scales.cwiseInverse().asDiagonal();
  if (observable) {
    observable->assign(static_cast<std::size_t>(m), true);
    for (Eigen::Index j = 0; j < m; ++j)
      if (Qr.cols() > 0 && Qr.row(j).norm() > 0.05)
        (*observable)[static_cast<std::size_t>(j)] = false;
  }
  return M;
}

}  // namespace rotacal
