// A finding judged again with each noise stream's lag-1 correlation at the upper bound of its
// confidence interval (search.hpp: holds_at_correlation_bound). The search judges a candidate
// under the AR model of what the extended model leaves; where the noise is one short stream
// that estimate spreads widely (a touch probe's 120 touches, after the fit's 11 directions:
// 0.43 +- 0.09 for a true 0.5), and a session whose correlation comes out low weighs a slow
// shape against too little long-run variance. Where the data cannot tell whether the noise is
// slow enough to hold the shape, the answer is no finding.
#include <algorithm>
#include <cmath>

#include "rotacal/core/stats.hpp"
#include "search.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// Burg's lag-1 reflection coefficient of a stream's values x (time order), mean removed.
double lag1_reflection(const Eigen::VectorXd& residuals, const std::vector<Eigen::Index>& rows) {
  double mean = 0.0;
  for (Eigen::Index i : rows) mean += residuals[i];
  mean /= static_cast<double>(rows.size());
  double num = 0.0, den = 0.0;
  for (std::size_t t = 1; t < rows.size(); ++t) {
    const double a = residuals[rows[t]] - mean, b = residuals[rows[t - 1]] - mean;
    num += 2.0 * a * b;
    den += a * a + b * b;
  }
  return den > 0.0 ? num / den : 0.0;
}

// Prais-Winsten whitening of each stream of M's rows by its AR(1) coefficient rho[s] (scale
// left out: the tests below take ratios): w_0 = sqrt(1 - rho^2) x_0, w_t = x_t - rho x_{t-1}.
Eigen::MatrixXd whitened_ar1(const NoiseStreamLayout& layout, const std::vector<double>& rho, const Eigen::MatrixXd& M) {
  Eigen::MatrixXd W = M;
  for (std::size_t s = 0; s < layout.rows.size(); ++s) {
    const std::vector<Eigen::Index>& rows = layout.rows[s];
    for (std::size_t t = rows.size(); t-- > 1;) W.row(rows[t]) -= rho[s] * M.row(rows[t - 1]);
    if (!rows.empty()) W.row(rows.front()) *= std::sqrt(1.0 - rho[s] * rho[s]);
  }
  return W;
}

// |y - X b|^2 at the least-squares b.
double residual_ss(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  const Eigen::MatrixXd Q = orthonormal_basis(X);
  return (y - Q * (Q.transpose() * y)).squaredNorm();
}

}  // namespace

bool holds_at_correlation_bound(const SearchContext& S, const Round& R, const Score& s, const ModelFit& fit,
                                const ModelFit& refit, double m_tests) {
  const double z = S.P.correlation_bound_z();
  const std::size_t ci = static_cast<std::size_t>(&s - R.scores.data());
  // The 1/f-like treatment (levels, random walk) bounds its noise by the declared variance.
  if (!(z > 0.0) || R.levels_of[ci] || R.treatment_of[ci].full || s.X.cols() <= R.in.Jfree.cols()) return true;
  const double n = static_cast<double>(refit.residuals.size());
  std::vector<double> rho(S.layout.rows.size(), 0.0);
  for (std::size_t st = 0; st < rho.size(); ++st) {
    const double ns = static_cast<double>(S.layout.rows[st].size());
    if (ns < 3.0) continue;
    // Burg's estimate, corrected for the stream's mean as with_mean_bias_corrected does, and its
    // sampling sigma with the degrees of freedom the fit leaves the stream (its share of them).
    const double k = lag1_reflection(refit.residuals, S.layout.rows[st]);
    const double rho_hat = std::clamp(k + (1.0 + 3.0 * k) / ns, 0.0, 0.995);
    const double dof = std::max(2.0, ns - refit.num_free * ns / n);
    rho[st] = std::min(0.995, rho_hat + z * std::sqrt((1.0 - rho_hat * rho_hat) / dof));
  }
  const Eigen::Index p = R.in.Jfree.cols();
  Eigen::MatrixXd M(s.X.rows(), s.X.cols() + 1);
  M << s.X, fit.residuals;
  const Eigen::MatrixXd W = whitened_ar1(S.layout, rho, M);
  const Eigen::VectorXd y = W.col(W.cols() - 1);
  const double rss0 = residual_ss(W.leftCols(p), y);
  const double rss1 = std::max(residual_ss(W.leftCols(s.X.cols()), y), 1e-300);
  const double delta_bic = n * std::log(rss1 / rss0) + s.k * std::log(n);
  const double dof = n - fit.num_free - s.k;
  const double F = ((rss0 - rss1) / s.k) / (rss1 / dof);
  return delta_bic < S.options.min_delta_bic && stats::f_sf(std::max(F, 0.0), s.k, dof) < S.options.alpha / m_tests;
}

}  // namespace rotacal::diagnosis_detail
