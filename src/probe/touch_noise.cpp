// SPDX-License-Identifier: BSD-3-Clause
// The touch probe's noise model: the three coordinates' AR(1) seen along each approach
// (probe/touch_noise.hpp).
#include "rotacal/probe/touch_noise.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

TouchNoiseWhitener::TouchNoiseWhitener(std::vector<Eigen::Index> rows,
                                       const std::vector<Eigen::Vector3d>& n, double rho,
                                       double sigma_mm, Eigen::Index size)
    : rows_(std::move(rows)), rho_(rho), size_(size) {
  if (!(sigma_mm > 0.0) || !std::isfinite(sigma_mm) || !(std::abs(rho) < 1.0))
    throw InvalidArgument("TouchNoiseWhitener: needs sigma > 0 and |rho| < 1");
  if (n.size() != rows_.size()) throw InvalidArgument("TouchNoiseWhitener: one direction per row");
  // The Kalman filter of the state s_i (the three coordinates' noise): s_i = rho s_{i-1} + w_i,
  // Var w = sigma^2 (1 - rho^2) I, started stationary; the residual reads n_i . s_i.
  const double s2 = sigma_mm * sigma_mm;
  Eigen::Matrix3d P = s2 * Eigen::Matrix3d::Identity();
  for (std::size_t t = 0; t < rows_.size(); ++t) {
    if (!(n[t].norm() > 0.0) || rows_[t] < 0 || rows_[t] >= size_)
      throw InvalidArgument("TouchNoiseWhitener: a zero direction or a row outside the fit");
    const Eigen::Vector3d u = n[t].normalized(), Pu = P * u;
    const double F = u.dot(Pu);  // >= sigma^2 (1 - rho^2) after the first step
    n_.push_back(u);
    gain_.push_back(Pu / F);
    inv_sd_.push_back(1.0 / std::sqrt(F));
    log_det_ += std::log(F);
    P -= Pu * Pu.transpose() / F;
    P = rho * rho * P + s2 * (1.0 - rho * rho) * Eigen::Matrix3d::Identity();
  }
}

void TouchNoiseWhitener::apply(Eigen::Ref<Eigen::MatrixXd> columns) const {
  if (columns.rows() != size_)
    throw InvalidArgument("TouchNoiseWhitener::apply: " + std::to_string(columns.rows()) +
                          " rows given, the model covers " + std::to_string(size_));
  for (Eigen::Index c = 0; c < columns.cols(); ++c) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();  // predicted state mean
    for (std::size_t t = 0; t < rows_.size(); ++t) {
      double& y = columns(rows_[t], c);
      const double v = y - n_[t].dot(m);
      y = v * inv_sd_[t];
      m = rho_ * (m + gain_[t] * v);
    }
  }
}

namespace {

struct Reml {
  std::vector<Eigen::Index> rows;
  std::vector<Eigen::Vector3d> n;
  Eigen::Index size = 0;
  Eigen::MatrixXd A;  // [X y], X's columns at unit norm (the criterion depends on its span)

  // -2 restricted log-likelihood (up to a constant) at rho, sigma profiled out; `rss` gets the
  // whitened residual sum of squares at sigma 1 and `k` the rank of X.
  double operator()(double rho, double* rss = nullptr, Eigen::Index* k = nullptr) const {
    const TouchNoiseWhitener W(rows, n, rho, 1.0, size);
    Eigen::MatrixXd B = A;
    W.apply(B);
    const Eigen::Index p = B.cols() - 1;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(B.leftCols(p));
    const Eigen::Index r = qr.rank();
    Eigen::VectorXd y = B.col(p);
    y.applyOnTheLeft(qr.householderQ().adjoint());
    const double ss = std::max(y.tail(y.size() - r).squaredNorm(), 1e-300);
    double logdet_xvx = 0.0;
    for (Eigen::Index j = 0; j < r; ++j) logdet_xvx += 2.0 * std::log(std::abs(qr.matrixR()(j, j)));
    const double dof = static_cast<double>(y.size() - r);
    if (rss) *rss = ss;
    if (k) *k = r;
    return dof * std::log(ss / dof) + W.log_det() + logdet_xvx;
  }
};

}  // namespace

TouchNoise estimate_touch_noise(const ProbeSession& session, const Eigen::VectorXd& residuals_mm,
                                const Eigen::MatrixXd& free_jacobian) {
  const auto N = static_cast<Eigen::Index>(session.samples.size());
  if (residuals_mm.size() != N || free_jacobian.rows() != N)
    throw InvalidArgument("estimate_touch_noise: one residual and Jacobian row per touch");
  Reml f;
  f.size = N;
  f.rows.resize(session.samples.size());
  std::iota(f.rows.begin(), f.rows.end(), Eigen::Index{0});
  std::stable_sort(f.rows.begin(), f.rows.end(), [&](Eigen::Index a, Eigen::Index b) {
    return session.samples[static_cast<std::size_t>(a)].time <
           session.samples[static_cast<std::size_t>(b)].time;
  });
  for (Eigen::Index i : f.rows) f.n.push_back(session.samples[static_cast<std::size_t>(i)].n);
  f.A.resize(N, free_jacobian.cols() + 1);
  for (Eigen::Index j = 0; j < free_jacobian.cols(); ++j) {
    const double s = free_jacobian.col(j).norm();
    f.A.col(j) = s > 0.0 ? Eigen::VectorXd(free_jacobian.col(j) / s) : free_jacobian.col(j);
  }
  f.A.col(free_jacobian.cols()) = residuals_mm;
  // Golden-section search of rho over [0, 0.95] (the criterion is smooth and, in the sessions
  // tried, unimodal there), then the lower end compared: white when that is as likely.
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = 0.0, b = 0.95, c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int it = 0; it < 40 && b - a > 1e-4; ++it) {
    if (fc < fd)
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = f(c);
    else
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = f(d);
  }
  double rho = fc < fd ? c : d;
  if (f(0.0) <= std::min(fc, fd)) rho = 0.0;
  double rss = 0.0;
  Eigen::Index k = 0;
  f(rho, &rss, &k);
  TouchNoise out;
  out.rho = rho;
  out.sigma_mm = std::sqrt(rss / std::max<double>(1.0, static_cast<double>(N - k)));
  if (rho > 0.0 && out.sigma_mm > 0.0)
    out.whitener = std::make_shared<TouchNoiseWhitener>(f.rows, f.n, rho, out.sigma_mm, N);
  // Described as one AR(1) stream of the coordinates (the model the reports and files know).
  NoiseModel& M = out.described;
  NoiseStream S;
  S.group = "touches";
  S.rows = f.rows;
  if (rho > 0.0) S.ar = S.reflection = {rho};
  S.marginal_sigma_um = out.sigma_mm * 1e3;
  S.innovation_sigma_um = S.marginal_sigma_um * std::sqrt(1.0 - rho * rho);
  std::vector<double> dt;
  for (std::size_t t = 1; t < f.rows.size(); ++t)
    dt.push_back(session.samples[static_cast<std::size_t>(f.rows[t])].time -
                 session.samples[static_cast<std::size_t>(f.rows[t - 1])].time);
  if (!dt.empty()) {
    std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
    S.sample_interval_s = dt[dt.size() / 2];
  }
  const double ns = static_cast<double>(N);
  S.correlation_samples = std::min(ns, (1.0 + rho) / (1.0 - rho));
  S.correlation_time_s = S.correlation_samples * S.sample_interval_s;
  S.effective_samples = ns / S.correlation_samples;
  M.n = session.samples.size();
  M.sigma_um = S.marginal_sigma_um;
  M.innovation_sigma_um = S.innovation_sigma_um;
  M.correlation_samples = S.correlation_samples;
  M.correlation_time_s = S.correlation_time_s;
  M.effective_samples = S.effective_samples;
  M.max_order = rho > 0.0 ? 1 : 0;
  M.streams.push_back(std::move(S));
  return out;
}

Eigen::VectorXd draw_touch_noise(const ProbeSession& session, double rho, double sigma_mm,
                                 std::mt19937_64& rng) {
  if (!(std::abs(rho) < 1.0) || !(sigma_mm >= 0.0))
    throw InvalidArgument("draw_touch_noise: needs |rho| < 1 and sigma >= 0");
  std::vector<std::size_t> order(session.samples.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return session.samples[a].time < session.samples[b].time;
  });
  std::normal_distribution<double> g(0.0, 1.0);
  const auto white3 = [&] { return Eigen::Vector3d(g(rng), g(rng), g(rng)); };
  Eigen::Vector3d state = sigma_mm * white3();  // started stationary
  const double innovation = sigma_mm * std::sqrt(1.0 - rho * rho);
  Eigen::VectorXd e(static_cast<Eigen::Index>(order.size()));
  for (std::size_t t = 0; t < order.size(); ++t) {
    if (t > 0) state = rho * state + innovation * white3();
    const std::size_t i = order[t];
    e[static_cast<Eigen::Index>(i)] = session.samples[i].n.normalized().dot(state);
  }
  return e;
}

OwnNoiseModel touch_noise_model(std::shared_ptr<const ProbeSession> session) {
  return [session](const JointFitOutcome& white,
                   NoiseModel& described) -> std::shared_ptr<const ResidualWhitener> {
    TouchNoise t = estimate_touch_noise(*session, white.residuals, free_jacobian(white));
    described = std::move(t.described);
    return t.whitener;
  };
}

}  // namespace rotacal
