// The yield convention for effects that share directions with the baseline (yield_convention.hpp).
#include "rotacal/core/yield_convention.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>

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
  for (Eigen::Index c = 0; c < k; ++c) Ns.col(c) = o.null_space[static_cast<std::size_t>(c)].cwiseQuotient(scales);
  const Eigen::MatrixXd Q = Ns.householderQr().householderQ() * Eigen::MatrixXd::Identity(m, k);
  // Its yielding part, and the directions in which that part is not negligible.
  Eigen::MatrixXd A(static_cast<Eigen::Index>(y.size()), k);
  for (std::size_t r = 0; r < y.size(); ++r) A.row(static_cast<Eigen::Index>(r)) = Q.row(y[r]);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index g = 0;
  while (g < sv.size() && sv[g] > 0.05) ++g;
  if (g == 0) return {};
  const Eigen::MatrixXd Qg = Q * svd.matrixV().leftCols(g);   // resolved directions
  const Eigen::MatrixXd Qr = Q * svd.matrixV().rightCols(k - g);  // left as they are
  const Eigen::MatrixXd Ag = A * svd.matrixV().leftCols(g);
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
      if (Qr.cols() > 0 && Qr.row(j).norm() > 0.05) (*observable)[static_cast<std::size_t>(j)] = false;
  }
  return M;
}

}  // namespace rotacal
