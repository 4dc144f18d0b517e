// SPDX-License-Identifier: BSD-3-Clause
// The exact AR prewhitener of a noise model (noise_model.hpp), its inverse covariance and
// Gram matrix, the AR(1) + random-walk filter, and the AR autocovariance of a stream.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "levinson.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"

namespace rotacal {

using noise_detail::levinson;

std::vector<double> ar_autocovariance(const NoiseStream& s, std::size_t n) {
  std::vector<double> g(n, 0.0);
  if (n == 0) return g;
  const std::vector<std::vector<double>> phi = levinson(s.reflection);
  double v = std::pow(s.marginal_sigma_um * 1e-3, 2);
  g[0] = v;
  const std::size_t p = s.reflection.size();
  for (std::size_t m = 1; m < n; ++m) {
    if (m <= p) {
      // Levinson read backwards: k_m = (gamma_m - sum_j phi_{m-1,j} gamma_{m-j}) / v_{m-1}.
      double acc = s.reflection[m - 1] * v;
      for (std::size_t j = 1; j < m; ++j) acc += phi[m - 1][j - 1] * g[m - j];
      g[m] = acc;
      v *= 1.0 - s.reflection[m - 1] * s.reflection[m - 1];
    } else {
      double acc = 0.0;
      for (std::size_t j = 1; j <= p; ++j) acc += phi[p][j - 1] * g[m - j];
      g[m] = acc;
    }
  }
  return g;
}

Eigen::MatrixXd stream_covariance(const NoiseStream& s) {
  const Eigen::Index n = static_cast<Eigen::Index>(s.rows.size());
  const std::vector<double> g = ar_autocovariance(s, s.rows.size());
  const double q2 = std::pow(s.random_walk_step_um * 1e-3, 2);
  Eigen::MatrixXd C(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      C(i, j) =
          g[static_cast<std::size_t>(std::abs(i - j))] + q2 * static_cast<double>(std::min(i, j));
  return C;
}

ArWalkFilter::ArWalkFilter(std::size_t n, double marginal_var, double rho, double step_var)
    : rho_(rho) {
  if (!(marginal_var > 0.0) || !(step_var >= 0.0) || !(std::abs(rho) < 1.0))
    throw InvalidArgument("ArWalkFilter: needs marginal_var > 0, step_var >= 0 and |rho| < 1");
  gain_a_.resize(n), gain_w_.resize(n), inv_sd_.resize(n);
  // Predicted state covariance [[p00, p01], [p01, p11]] of (a_t, w_t): stationary a, w_0 = 0.
  double p00 = marginal_var, p01 = 0.0, p11 = 0.0;
  const double innov = marginal_var * (1.0 - rho * rho);
  for (std::size_t t = 0; t < n; ++t) {
    const double F = p00 + 2.0 * p01 + p11;  // Var of the reading's innovation (Z = [1 1])
    const double ka = (p00 + p01) / F, kw = (p01 + p11) / F;
    gain_a_[t] = ka, gain_w_[t] = kw, inv_sd_[t] = 1.0 / std::sqrt(F);
    log_det_ += std::log(F);
    // Update (P - F k k^T), then predict (T = diag(rho, 1), Q = diag(innov, step_var)).
    const double f00 = p00 - F * ka * ka, f01 = p01 - F * ka * kw, f11 = p11 - F * kw * kw;
    p00 = rho * rho * f00 + innov;
    p01 = rho * f01;
    p11 = f11 + step_var;
  }
}

void ArWalkFilter::apply(const std::vector<Eigen::Index>& rows,
                         Eigen::Ref<Eigen::MatrixXd> columns) const {
  const std::size_t n = inv_sd_.size();
  if (rows.size() != n) throw InvalidArgument("ArWalkFilter::apply: rows and filter sizes differ");
  // Four columns at a time, interleaved: each column's arithmetic and its order are those
  // of the one-column loop below (bit-identical), but the four recursions' latencies overlap
  // (the filter is a serial chain per column): 82-136 -> 21-40 us a call on 360 readings x 30
  // columns, at load 4-8.
  constexpr Eigen::Index kLanes = 4;
  Eigen::Index c = 0;
  for (; c + kLanes <= columns.cols(); c += kLanes) {
    double ma[kLanes] = {}, mw[kLanes] = {};  // predicted state means
    for (std::size_t t = 0; t < n; ++t) {
      const Eigen::Index r = rows[t];
      const double ga = gain_a_[t], gw = gain_w_[t], is = inv_sd_[t];
      for (Eigen::Index k = 0; k < kLanes; ++k) {
        double& y = columns(r, c + k);
        const double v = y - ma[k] - mw[k];
        y = v * is;
        ma[k] = rho_ * (ma[k] + ga * v);
        mw[k] += gw * v;
      }
    }
  }
  for (; c < columns.cols(); ++c) {
    double ma = 0.0, mw = 0.0;  // predicted state mean
    for (std::size_t t = 0; t < n; ++t) {
      double& y = columns(rows[t], c);
      const double v = y - ma - mw;
      y = v * inv_sd_[t];
      ma = rho_ * (ma + gain_a_[t] * v);
      mw += gain_w_[t] * v;
    }
  }
}

ArWhitener::ArWhitener(const NoiseModel& model, double residual_unit_mm) : n_(model.n) {
  if (!(residual_unit_mm > 0.0) || !std::isfinite(residual_unit_mm))
    throw InvalidArgument("ArWhitener: residual_unit_mm must be positive and finite");
  for (const NoiseStream& s : model.streams) {
    Stream w;
    w.rows = s.rows;
    w.phi = levinson(s.reflection);
    // v_m = v_0 prod (1 - k_j^2), in column units.
    double v = std::pow(s.marginal_sigma_um * 1e-3 / residual_unit_mm, 2);
    if (!(v > 0.0)) v = 1.0;  // a stream of zeros: nothing to scale
    for (std::size_t m = 0; m < w.phi.size(); ++m) {
      if (m > 0) v *= 1.0 - s.reflection[m - 1] * s.reflection[m - 1];
      w.inv_sd.push_back(1.0 / std::sqrt(std::max(v, 1e-300)));
    }
    if (s.random_walk_step_um > 0.0 && !s.rows.empty() && s.order() <= 1) {
      const double u2 = residual_unit_mm * residual_unit_mm;
      w.walk.emplace_back(
          s.rows.size(), std::max(std::pow(s.marginal_sigma_um * 1e-3, 2) / u2, 1e-300),
          s.order() == 1 ? s.reflection[0] : 0.0, std::pow(s.random_walk_step_um * 1e-3, 2) / u2);
    } else if (s.random_walk_step_um > 0.0 && !s.rows.empty()) {
      const Eigen::MatrixXd C = stream_covariance(s) / (residual_unit_mm * residual_unit_mm);
      const Eigen::LLT<Eigen::MatrixXd> llt(C);
      if (llt.info() != Eigen::Success)
        throw InvalidArgument("ArWhitener: the covariance of stream " + s.group + " channel " +
                              std::to_string(s.channel) + " is not positive definite");
      w.chol = llt.matrixL();
    }
    streams_.push_back(std::move(w));
  }
}

void ArWhitener::apply(Eigen::Ref<Eigen::MatrixXd> columns) const {
  if (static_cast<std::size_t>(columns.rows()) != n_)
    throw InvalidArgument("ArWhitener::apply: " + std::to_string(columns.rows()) +
                          " rows given, the noise model covers " + std::to_string(n_));
  std::vector<double> x;
  Eigen::MatrixXd block;
  for (const Stream& s : streams_) {
    const std::size_t n = s.rows.size(), p = s.phi.size() - 1;
    if (!s.walk.empty()) {
      s.walk.front().apply(s.rows, columns);
      continue;
    }
    if (s.chol.size() > 0) {
      // Dense: L^-1 x for every column at once (L L^T = the stream's covariance).
      block.resize(static_cast<Eigen::Index>(n), columns.cols());
      for (std::size_t t = 0; t < n; ++t)
        block.row(static_cast<Eigen::Index>(t)) = columns.row(s.rows[t]);
      s.chol.triangularView<Eigen::Lower>().solveInPlace(block);
      for (std::size_t t = 0; t < n; ++t)
        columns.row(s.rows[t]) = block.row(static_cast<Eigen::Index>(t));
      continue;
    }
    if (p <= 1 && n > 0) {
      // White or AR(1), the common streams: the recursion below without its per-reading
      // lookups (the same arithmetic, in the same order).
      const double a = s.inv_sd[0], b = p == 1 ? s.inv_sd[1] : a, phi = p == 1 ? s.phi[1][0] : 0.0;
      for (Eigen::Index c = 0; c < columns.cols(); ++c) {
        double& y0 = columns(s.rows[0], c);
        double prev = y0;
        y0 = prev * a;
        for (std::size_t t = 1; t < n; ++t) {
          double& y = columns(s.rows[t], c);
          const double xt = y;
          y = (xt - phi * prev) * b;
          prev = xt;
        }
      }
      continue;
    }
    x.resize(n);
    for (Eigen::Index c = 0; c < columns.cols(); ++c) {
      for (std::size_t t = 0; t < n; ++t) x[t] = columns(s.rows[t], c);
      // Start-up rows use the order t prediction (exact Cholesky factor), then order p.
      for (std::size_t t = 0; t < n; ++t) {
        const std::size_t m = std::min(t, p);
        const std::vector<double>& phi = s.phi[m];
        double e = x[t];
        for (std::size_t j = 1; j <= m; ++j) e -= phi[j - 1] * x[t - j];
        columns(s.rows[t], c) = e * s.inv_sd[m];
      }
    }
  }
}

bool ArWhitener::ar1_only() const {
  for (const Stream& s : streams_)
    if (!s.walk.empty() || s.chol.size() > 0 || s.phi.size() > 2) return false;
  return true;
}

void ArWhitener::apply_inverse_covariance(Eigen::Ref<Eigen::MatrixXd> columns) const {
  if (!ar1_only())
    throw InvalidArgument(
        "ArWhitener::apply_inverse_covariance: needs AR order <= 1 without a random walk");
  // V^-1 = W^T W of the start-up row e_0 = a x_0 and the rows e_t = b (x_t - phi x_{t-1})
  // (apply()) is tridiagonal per stream: diagonal a^2 + b^2 phi^2, b^2 (1 + phi^2), ..., b^2 and
  // -b^2 phi beside it. One pass per column (the candidates' products at rho 0.5 spent most of
  // their time in whitening and then applying W^T, two passes).
  for (const Stream& s : streams_) {
    const std::size_t n = s.rows.size();
    if (n == 0) continue;
    const double a = s.inv_sd[0];
    if (s.phi.size() < 2 || n == 1) {
      for (Eigen::Index c = 0; c < columns.cols(); ++c)
        for (const Eigen::Index r : s.rows) columns(r, c) *= a * a;
      continue;
    }
    const double b = s.inv_sd[1], phi = s.phi[1][0];
    const double b2 = b * b, off = -b2 * phi, first = a * a + b2 * phi * phi,
                 mid = b2 * (1.0 + phi * phi);
    for (Eigen::Index c = 0; c < columns.cols(); ++c) {
      double prev = 0.0;  // x_{t-1}, before its row was overwritten
      double x = columns(s.rows[0], c);
      for (std::size_t t = 0; t < n; ++t) {
        const double next = t + 1 < n ? columns(s.rows[t + 1], c) : 0.0;
        const double diag = t == 0 ? first : t + 1 < n ? mid : b2;
        columns(s.rows[t], c) = diag * x + off * (prev + next);
        prev = x;
        x = next;
      }
    }
  }
}

StreamLagProducts::StreamLagProducts(const Eigen::MatrixXd& J,
                                     std::vector<std::vector<Eigen::Index>> stream_rows)
    : rows(std::move(stream_rows)) {
  const Eigen::Index p = J.cols();
  std::vector<char> covered(static_cast<std::size_t>(J.rows()), 0);
  Eigen::MatrixXd block;
  for (const std::vector<Eigen::Index>& r : rows) {
    const Eigen::Index m = static_cast<Eigen::Index>(r.size());
    block.resize(m, p);
    for (Eigen::Index t = 0; t < m; ++t) {
      block.row(t) = J.row(r[static_cast<std::size_t>(t)]);
      covered[static_cast<std::size_t>(r[static_cast<std::size_t>(t)])] = 1;
    }
    S.push_back(block.transpose() * block);
    U.push_back(m > 1 ? Eigen::MatrixXd(block.bottomRows(m - 1).transpose() * block.topRows(m - 1))
                      : Eigen::MatrixXd::Zero(p, p));
    first.push_back(m ? Eigen::MatrixXd(block.row(0).transpose() * block.row(0))
                      : Eigen::MatrixXd::Zero(p, p));
    last.push_back(m ? Eigen::MatrixXd(block.row(m - 1).transpose() * block.row(m - 1))
                     : Eigen::MatrixXd::Zero(p, p));
  }
  rest = Eigen::MatrixXd::Zero(p, p);
  for (Eigen::Index i = 0; i < J.rows(); ++i)
    if (!covered[static_cast<std::size_t>(i)]) rest += J.row(i).transpose() * J.row(i);
}

Eigen::MatrixXd ArWhitener::gram(const StreamLagProducts& lags) const {
  if (!ar1_only())
    throw InvalidArgument("ArWhitener::gram: needs AR order <= 1 without a random walk");
  if (lags.rows.size() != streams_.size())
    throw InvalidArgument("ArWhitener::gram: the lag products have " +
                          std::to_string(lags.rows.size()) + " streams, the noise model " +
                          std::to_string(streams_.size()));
  Eigen::MatrixXd G = lags.rest;
  for (std::size_t k = 0; k < streams_.size(); ++k) {
    const Stream& s = streams_[k];
    if (s.rows != lags.rows[k])
      throw InvalidArgument("ArWhitener::gram: stream " + std::to_string(k) +
                            " has other rows than the lag products");
    if (s.rows.empty()) continue;
    const double a2 = s.inv_sd[0] * s.inv_sd[0];
    if (s.phi.size() < 2) {
      G += a2 * lags.S[k];
      continue;
    }
    const double b2 = s.inv_sd[1] * s.inv_sd[1], phi = s.phi[1][0];
    G += a2 * lags.first[k] +
         b2 * ((1.0 + phi * phi) * lags.S[k] - lags.first[k] - phi * phi * lags.last[k] -
               phi * (lags.U[k] + lags.U[k].transpose()));
  }
  return G;
}

}  // namespace rotacal
