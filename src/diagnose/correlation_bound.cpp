// SPDX-License-Identifier: BSD-3-Clause
// A finding judged again with each noise stream's lag-1 correlation at the upper bound of its
// confidence interval (search.hpp: holds_at_correlation_bound). The search judges a candidate
// under the AR model of what the extended model leaves; where the noise is one short stream
// that estimate spreads widely (a touch probe's 120 touches, after the fit's 11 directions:
// 0.43 +- 0.09 for a true 0.5), and a session whose correlation comes out low weighs a slow
// shape against too little long-run variance. Where the data cannot tell whether the noise is
// slow enough to hold the shape, the answer is no finding.
#include <algorithm>
#include <cmath>

#include "rotacal/core/noise_model.hpp"
#include "rotacal/core/stats.hpp"
#include "search.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// |y - X b|^2 at the least-squares b.
double residual_ss(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  const Eigen::MatrixXd Q = orthonormal_basis(X);
  return (y - Q * (Q.transpose() * y)).squaredNorm();
}

}  // namespace

bool holds_at_correlation_bound(const SearchContext& S, const Round& R, const Score& s,
                                const ModelFit& fit, const ModelFit& refit, double m_tests) {
  const double z = S.P.correlation_bound_z();
  const std::size_t ci = static_cast<std::size_t>(&s - R.scores.data());
  // The 1/f-like treatment (levels, random walk) bounds its noise by the declared variance.
  if (!(z > 0.0) || R.levels_of[ci] || R.treatment_of[ci].full || s.X.cols() <= R.in.Jfree.cols())
    return true;
  const double n = static_cast<double>(refit.residuals.size());
  // Each stream's lag-1 coefficient (Burg's, at order 1 even where BIC would call the stream
  // white), corrected for the stream's mean, then raised to the upper bound of its confidence
  // interval: its sampling sigma with the degrees of freedom the fit leaves the stream (its
  // share of them). Streams too short for an AR fit stay white.
  NoiseModelOptions lag1;
  lag1.max_order = lag1.min_order = 1;
  const NoiseModel estimated =
      with_mean_bias_corrected(estimate_noise_model(S.layout, refit.residuals, lag1));
  std::vector<double> rho(estimated.streams.size(), 0.0);
  for (std::size_t st = 0; st < rho.size(); ++st) {
    const NoiseStream& stream = estimated.streams[st];
    if (stream.order() != 1) continue;
    const double ns = static_cast<double>(stream.rows.size());
    const double rho_hat = std::clamp(stream.ar[0], 0.0, 0.995);
    const double dof = std::max(2.0, ns - refit.num_free * ns / n);
    rho[st] = std::min(0.995, rho_hat + z * std::sqrt((1.0 - rho_hat * rho_hat) / dof));
  }
  const Eigen::Index p = R.in.Jfree.cols();
  Eigen::MatrixXd W(s.X.rows(), s.X.cols() + 1);
  W << s.X, fit.residuals;
  ArWhitener(with_lag1(estimated, rho)).apply(W);
  const Eigen::VectorXd y = W.col(W.cols() - 1);
  const double rss0 = residual_ss(W.leftCols(p), y);
  const double rss1 = std::max(residual_ss(W.leftCols(s.X.cols()), y), 1e-300);
  const double delta_bic = n * std::log(rss1 / rss0) + s.k * std::log(n);
  const double dof = n - fit.num_free - s.k;
  const double F = ((rss0 - rss1) / s.k) / (rss1 / dof);
  return delta_bic < S.options.min_delta_bic &&
         stats::f_sf(std::max(F, 0.0), s.k, dof) < S.options.alpha / m_tests;
}

}  // namespace rotacal::diagnosis_detail
