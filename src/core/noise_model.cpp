// Residual noise model: per-stream AR(p) by Burg with BIC order selection, the exact AR
// prewhitener, and seeded coloured-noise generators.
#include "rotacal/core/noise_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <sstream>

#include <Eigen/Cholesky>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

// One order m of Burg's recursion on a segment's forward and backward prediction errors f, b:
// adds its sums of f_t b_{t-1} and f_t^2 + b_{t-1}^2 over t = m..n-1. Written on Eigen
// segments so that they vectorise: the diagnosis models the residual of every candidate.
void burg_sums(const Eigen::VectorXd& f, const Eigen::VectorXd& b, Eigen::Index m, double* num, double* den) {
  const Eigen::Index len = f.size() - m;
  if (len <= 0) return;
  const auto fs = f.segment(m, len);
  const auto bs = b.segment(m - 1, len);
  *num += fs.dot(bs);
  *den += fs.squaredNorm() + bs.squaredNorm();
}

// f_t <- f_t - k b_{t-1} and b_t <- b_{t-1} - k f_t for t = m..n-1, both from order m-1's values.
void burg_update(Eigen::VectorXd& f, Eigen::VectorXd& b, Eigen::Index m, double km) {
  const Eigen::Index len = f.size() - m;
  if (len <= 0) return;
  const Eigen::VectorXd bs = b.segment(m - 1, len);  // a copy: b_t is overwritten before b_{t+1} reads it
  b.segment(m, len) = bs - km * f.segment(m, len);
  f.segment(m, len) -= km * bs;
}

// Burg's recursion up to order P over one or more segments (one model for all: the sums run
// over every segment): reflection coefficients k_1..k_P and the prediction error variances
// v_0..v_P (v_0 = mean square of the readings).
void burg_pooled(std::vector<Eigen::VectorXd> f, int P, std::vector<double>* k, std::vector<double>* v,
                 std::size_t* n_total = nullptr) {
  double ss = 0.0;
  std::size_t n = 0;
  for (const Eigen::VectorXd& x : f) {
    ss += x.squaredNorm();
    n += static_cast<std::size_t>(x.size());
  }
  std::vector<Eigen::VectorXd> b = f;
  if (n_total) *n_total = n;
  k->clear();
  v->assign(1, n ? ss / static_cast<double>(n) : 0.0);
  for (int m = 1; m <= P; ++m) {
    double num = 0.0, den = 0.0;
    for (std::size_t s = 0; s < f.size(); ++s) burg_sums(f[s], b[s], m, &num, &den);
    const double km = den > 0.0 ? 2.0 * num / den : 0.0;
    for (std::size_t s = 0; s < f.size(); ++s) burg_update(f[s], b[s], m, km);
    k->push_back(km);
    v->push_back(v->back() * (1.0 - km * km));
  }
}

// Levinson: prediction coefficients of every order 0..p from the reflection coefficients
// (phi_{m,m} = k_m, phi_{m,j} = phi_{m-1,j} - k_m phi_{m-1,m-j}).
std::vector<std::vector<double>> levinson(const std::vector<double>& k) {
  std::vector<std::vector<double>> phi(1);
  for (std::size_t m = 1; m <= k.size(); ++m) {
    const std::vector<double>& prev = phi.back();
    std::vector<double> cur(m);
    cur[m - 1] = k[m - 1];
    for (std::size_t j = 0; j + 1 < m; ++j) cur[j] = prev[j] - k[m - 1] * prev[m - 2 - j];
    phi.push_back(std::move(cur));
  }
  return phi;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void check_sizes(const char* where, const std::vector<std::string>& groups,
                 const std::vector<double>& times) {
  if (groups.size() != times.size())
    throw InvalidArgument(std::string(where) + ": groups has " + std::to_string(groups.size()) +
                          " entries but times has " + std::to_string(times.size()));
  for (std::size_t i = 0; i < times.size(); ++i)
    if (!std::isfinite(times[i]))
      throw InvalidArgument(std::string(where) + ": times[" + std::to_string(i) + "] is not finite");
}

}  // namespace

std::vector<std::vector<Eigen::Index>> noise_streams(const std::vector<std::string>& groups,
                                                     const std::vector<double>& times,
                                                     std::vector<std::string>* stream_group,
                                                     std::vector<int>* stream_channel) {
  check_sizes("noise_streams", groups, times);
  // Rows by group in order of first appearance. Sessions hold long runs of one label, so the
  // map is searched only where the label changes (one string compare per reading otherwise).
  std::vector<std::string> order;
  std::vector<std::vector<Eigen::Index>> by_group;
  std::map<std::string, std::size_t> slot;
  std::size_t cur = 0;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (i == 0 || groups[i] != groups[i - 1]) {
      const auto it = slot.emplace(groups[i], order.size()).first;
      if (it->second == order.size()) order.push_back(groups[i]), by_group.emplace_back();
      cur = it->second;
    }
    by_group[cur].push_back(static_cast<Eigen::Index>(i));
  }
  std::vector<std::vector<Eigen::Index>> out;
  if (stream_group) stream_group->clear();
  if (stream_channel) stream_channel->clear();
  const auto time_of = [&](Eigen::Index row) { return times[static_cast<std::size_t>(row)]; };
  for (std::size_t g = 0; g < order.size(); ++g) {
    std::vector<Eigen::Index>& idx = by_group[g];
    // Rows come in time order in a session file: the (stable) sort is needed only when not.
    const auto earlier = [&](Eigen::Index a, Eigen::Index b) { return time_of(a) < time_of(b); };
    if (!std::is_sorted(idx.begin(), idx.end(), earlier)) std::stable_sort(idx.begin(), idx.end(), earlier);
    // Channel = position among the readings that share a time stamp (R-test dx, dy, dz).
    // Distinct time stamps (a ballbar test): one channel, the rows themselves.
    std::vector<std::vector<Eigen::Index>> ch;
    if (std::adjacent_find(idx.begin(), idx.end(), [&](Eigen::Index a, Eigen::Index b) {
          return time_of(a) == time_of(b);
        }) == idx.end()) {
      if (!idx.empty()) ch.push_back(std::move(idx));
    } else {
      for (std::size_t k = 0; k < idx.size();) {
        std::size_t e = k;
        while (e < idx.size() && time_of(idx[e]) == time_of(idx[k])) ++e;
        for (std::size_t c = 0; c < e - k; ++c) {
          if (ch.size() <= c) ch.emplace_back();
          ch[c].push_back(idx[k + c]);
        }
        k = e;
      }
    }
    for (std::size_t c = 0; c < ch.size(); ++c) {
      out.push_back(std::move(ch[c]));
      if (stream_group) stream_group->push_back(order[g]);
      if (stream_channel) stream_channel->push_back(static_cast<int>(c));
    }
  }
  return out;
}

NoiseStreamLayout::NoiseStreamLayout(const std::vector<std::string>& groups,
                                     const std::vector<double>& times)
    : n(groups.size()) {
  rows = noise_streams(groups, times, &group, &channel);
  sample_interval_s.reserve(rows.size());
  std::vector<double> dt;
  for (const std::vector<Eigen::Index>& s : rows) {
    dt.clear();
    for (std::size_t t = 1; t < s.size(); ++t) {
      const double d = times[static_cast<std::size_t>(s[t])] - times[static_cast<std::size_t>(s[t - 1])];
      if (d > 0.0) dt.push_back(d);
    }
    sample_interval_s.push_back(median(dt));
  }
}

NoiseStreamLayout NoiseStreamLayout::except_group(const std::string& name) const {
  NoiseStreamLayout out;
  out.n = n;
  for (std::size_t s = 0; s < rows.size(); ++s) {
    if (group[s] == name) continue;
    out.rows.push_back(rows[s]);
    out.group.push_back(group[s]);
    out.channel.push_back(channel[s]);
    out.sample_interval_s.push_back(sample_interval_s[s]);
  }
  return out;
}

NoiseModel estimate_noise_model(const std::vector<std::string>& groups,
                                const std::vector<double>& times,
                                const Eigen::VectorXd& residuals_mm,
                                const NoiseModelOptions& options) {
  if (static_cast<std::size_t>(residuals_mm.size()) != groups.size())
    throw InvalidArgument("estimate_noise_model: residuals has " +
                          std::to_string(residuals_mm.size()) + " entries but groups has " +
                          std::to_string(groups.size()));
  return estimate_noise_model(NoiseStreamLayout(groups, times), residuals_mm, options);
}

NoiseModel estimate_noise_model(const NoiseStreamLayout& layout, const Eigen::VectorXd& residuals_mm,
                                const NoiseModelOptions& options) {
  if (options.max_order < 0)
    throw InvalidArgument("estimate_noise_model: options.max_order is " +
                          std::to_string(options.max_order) + ", must be >= 0");
  if (static_cast<std::size_t>(residuals_mm.size()) != layout.n)
    throw InvalidArgument("estimate_noise_model: residuals has " +
                          std::to_string(residuals_mm.size()) + " entries but the session has " +
                          std::to_string(layout.n) + " readings");
  for (Eigen::Index i = 0; i < residuals_mm.size(); ++i)
    if (!std::isfinite(residuals_mm[i]))
      throw InvalidArgument("estimate_noise_model: residuals[" + std::to_string(i) +
                            "] is not finite");
  if (options.pooled && options.pool_only_if_all_coloured) {
    NoiseModelOptions own = options;
    own.pooled = false;
    NoiseModel each = estimate_noise_model(layout, residuals_mm, own);
    for (const NoiseStream& st : each.streams)
      if (st.order() == 0) return each;
    own.pooled = true;
    own.pool_only_if_all_coloured = false;
    return estimate_noise_model(layout, residuals_mm, own);
  }
  const auto& streams = layout.rows;
  const auto& sg = layout.group;
  const auto& sc = layout.channel;
  const auto& intervals = layout.sample_interval_s;
  NoiseModel M;
  M.n = layout.n;
  // Each stream's readings in time order with its mean removed.
  std::vector<Eigen::VectorXd> xs(streams.size());
  for (std::size_t s = 0; s < streams.size(); ++s) {
    xs[s] = residuals_mm(streams[s]);
    xs[s].array() -= xs[s].mean();
  }
  // BIC over orders 0..P of Burg's prediction error variances v_p for n readings.
  const auto choose = [](const std::vector<double>& v, std::size_t n) {
    int best = 0;
    double best_bic = 0.0;
    const double ln_n = std::log(static_cast<double>(std::max<std::size_t>(n, 2)));
    for (std::size_t p = 0; p < v.size(); ++p) {
      const double bic = static_cast<double>(n) * std::log(std::max(v[p], 1e-300)) + static_cast<double>(p) * ln_n;
      if (p == 0 || bic < best_bic) best = static_cast<int>(p), best_bic = bic;
    }
    return best;
  };
  std::vector<double> pooled_k, pooled_v;
  int pooled_order = 0;
  if (options.pooled) {
    std::size_t shortest = SIZE_MAX, total = 0;
    for (const auto& x : xs) shortest = std::min(shortest, static_cast<std::size_t>(x.size()));
    const int P = streams.empty() ? 0 : std::min(options.max_order, static_cast<int>(shortest / 4));
    burg_pooled(xs, std::max(P, 0), &pooled_k, &pooled_v, &total);
    pooled_order = choose(pooled_v, total);
  }
  double ss_marg = 0.0, ss_innov = 0.0;
  for (std::size_t s = 0; s < streams.size(); ++s) {
    NoiseStream S;
    S.group = sg[s];
    S.channel = sc[s];
    S.rows = streams[s];
    const std::size_t n = S.rows.size();
    S.sample_interval_s = intervals[s];
    std::vector<double> k, v;
    int best = 0;
    if (options.pooled) {
      // Shared coefficients, the stream's own variance: v_m = v_0 prod (1 - k_j^2).
      k = pooled_k, best = pooled_order;
      double v0 = 0.0;
      for (double xi : xs[s]) v0 += xi * xi;
      v.assign(1, n ? v0 / static_cast<double>(n) : 0.0);
      for (double kj : k) v.push_back(v.back() * (1.0 - kj * kj));
    } else {
      const int P = static_cast<int>(n) >= options.min_stream_size
                        ? std::min(options.max_order, static_cast<int>(n / 4))
                        : 0;
      std::vector<Eigen::VectorXd> one(1);
      one[0] = std::move(xs[s]);  // not read again
      burg_pooled(std::move(one), P, &k, &v);
      best = choose(v, n);
    }
    S.reflection.assign(k.begin(), k.begin() + best);
    S.ar = levinson(S.reflection).back();
    const double v0 = v[0], vp = v[static_cast<std::size_t>(best)];
    S.marginal_sigma_um = std::sqrt(v0) * 1e3;
    S.innovation_sigma_um = std::sqrt(vp) * 1e3;
    double sum_phi = 0.0;
    for (double a : S.ar) sum_phi += a;
    const double gap = std::max(1.0 - sum_phi, 1e-6);
    S.correlation_samples = v0 > 0.0 ? vp / (v0 * gap * gap) : 1.0;
    S.correlation_samples = std::min(S.correlation_samples, static_cast<double>(n));
    S.correlation_time_s = S.correlation_samples * S.sample_interval_s;
    S.effective_samples = std::min(static_cast<double>(n), static_cast<double>(n) / S.correlation_samples);
    ss_marg += v0 * static_cast<double>(n);
    ss_innov += vp * static_cast<double>(n);
    M.correlation_samples = std::max(M.correlation_samples, S.correlation_samples);
    M.correlation_time_s = std::max(M.correlation_time_s, S.correlation_time_s);
    M.effective_samples += S.effective_samples;
    M.max_order = std::max(M.max_order, best);
    M.streams.push_back(std::move(S));
  }
  if (M.n) {
    M.sigma_um = std::sqrt(ss_marg / static_cast<double>(M.n)) * 1e3;
    M.innovation_sigma_um = std::sqrt(ss_innov / static_cast<double>(M.n)) * 1e3;
  }
  return M;
}

NoiseModel with_mean_bias_corrected(const NoiseModel& model) {
  NoiseModel M = model;
  double ss_innov = 0.0;
  M.correlation_samples = 1.0, M.correlation_time_s = 0.0, M.effective_samples = 0.0;
  for (NoiseStream& S : M.streams) {
    const double n = static_cast<double>(S.rows.size());
    if (S.order() == 1 && S.random_walk_step_um == 0.0 && n > 0) {
      const double k = S.reflection[0];
      const double kc = std::min(0.995, k + (1.0 + 3.0 * k) / n);
      S.reflection[0] = S.ar[0] = kc;
      S.innovation_sigma_um = S.marginal_sigma_um * std::sqrt(1.0 - kc * kc);
      // AR(1): tau = s_e^2 / (s_x^2 (1 - phi)^2) = (1 + phi) / (1 - phi).
      S.correlation_samples = std::min((1.0 + kc) / (1.0 - kc), n);
      S.correlation_time_s = S.correlation_samples * S.sample_interval_s;
      S.effective_samples = std::min(n, n / S.correlation_samples);
    }
    ss_innov += std::pow(S.innovation_sigma_um, 2) * n;
    M.correlation_samples = std::max(M.correlation_samples, S.correlation_samples);
    M.correlation_time_s = std::max(M.correlation_time_s, S.correlation_time_s);
    M.effective_samples += S.effective_samples;
  }
  if (M.n) M.innovation_sigma_um = std::sqrt(ss_innov / static_cast<double>(M.n));
  return M;
}

std::string NoiseModel::summary() const {
  std::ostringstream out;
  out.precision(3);
  if (white()) out << "white";
  else {
    out << "AR(" << max_order << ")";
    // The coefficient of the largest stream, as the typical one.
    const NoiseStream* big = nullptr;
    for (const NoiseStream& s : streams)
      if (!big || s.rows.size() > big->rows.size()) big = &s;
    if (big && big->order() >= 1) out << ", phi_1 " << big->ar[0];
    if (random_walk_step_um > 0.0) out << " + random walk " << random_walk_step_um << " um per reading";
  }
  out << ", sigma " << sigma_um << " um (innovation " << innovation_sigma_um
      << " um), correlation time " << correlation_time_s << " s (" << correlation_samples
      << " samples), " << effective_samples << " effective samples of " << n;
  return out.str();
}

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
      C(i, j) = g[static_cast<std::size_t>(std::abs(i - j))] + q2 * static_cast<double>(std::min(i, j));
  return C;
}

ArWalkFilter::ArWalkFilter(std::size_t n, double marginal_var, double rho, double step_var) : rho_(rho) {
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

void ArWalkFilter::apply(const std::vector<Eigen::Index>& rows, Eigen::Ref<Eigen::MatrixXd> columns) const {
  const std::size_t n = inv_sd_.size();
  if (rows.size() != n) throw InvalidArgument("ArWalkFilter::apply: rows and filter sizes differ");
  for (Eigen::Index c = 0; c < columns.cols(); ++c) {
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
      w.walk.emplace_back(s.rows.size(), std::max(std::pow(s.marginal_sigma_um * 1e-3, 2) / u2, 1e-300),
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
      for (std::size_t t = 0; t < n; ++t) block.row(static_cast<Eigen::Index>(t)) = columns.row(s.rows[t]);
      s.chol.triangularView<Eigen::Lower>().solveInPlace(block);
      for (std::size_t t = 0; t < n; ++t) columns.row(s.rows[t]) = block.row(static_cast<Eigen::Index>(t));
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
    throw InvalidArgument("ArWhitener::apply_inverse_covariance: needs AR order <= 1 without a random walk");
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
    const double b2 = b * b, off = -b2 * phi, first = a * a + b2 * phi * phi, mid = b2 * (1.0 + phi * phi);
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

StreamLagProducts::StreamLagProducts(const Eigen::MatrixXd& J, std::vector<std::vector<Eigen::Index>> stream_rows)
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
    first.push_back(m ? Eigen::MatrixXd(block.row(0).transpose() * block.row(0)) : Eigen::MatrixXd::Zero(p, p));
    last.push_back(m ? Eigen::MatrixXd(block.row(m - 1).transpose() * block.row(m - 1)) : Eigen::MatrixXd::Zero(p, p));
  }
  rest = Eigen::MatrixXd::Zero(p, p);
  for (Eigen::Index i = 0; i < J.rows(); ++i)
    if (!covered[static_cast<std::size_t>(i)]) rest += J.row(i).transpose() * J.row(i);
}

Eigen::MatrixXd ArWhitener::gram(const StreamLagProducts& lags) const {
  if (!ar1_only()) throw InvalidArgument("ArWhitener::gram: needs AR order <= 1 without a random walk");
  if (lags.rows.size() != streams_.size())
    throw InvalidArgument("ArWhitener::gram: the lag products have " + std::to_string(lags.rows.size()) +
                          " streams, the noise model " + std::to_string(streams_.size()));
  Eigen::MatrixXd G = lags.rest;
  for (std::size_t k = 0; k < streams_.size(); ++k) {
    const Stream& s = streams_[k];
    if (s.rows != lags.rows[k])
      throw InvalidArgument("ArWhitener::gram: stream " + std::to_string(k) + " has other rows than the lag products");
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

namespace noise_gen {

namespace {
// AR(1) per stream with stationary start, unit... given marginal sigma.
void add_ar1(const std::vector<std::vector<Eigen::Index>>& streams, double rho, double sigma,
             std::mt19937_64& rng, Eigen::VectorXd& out) {
  std::normal_distribution<double> N(0.0, 1.0);
  const double innov = sigma * std::sqrt(std::max(0.0, 1.0 - rho * rho));
  for (const auto& s : streams) {
    double x = sigma * N(rng);
    for (std::size_t t = 0; t < s.size(); ++t) {
      if (t > 0) x = rho * x + innov * N(rng);
      out[s[t]] += x;
    }
  }
}
}  // namespace

Eigen::VectorXd ar1(const std::vector<std::string>& groups, const std::vector<double>& times,
                    double rho, double sigma_mm, std::uint64_t seed) {
  if (!(std::abs(rho) < 1.0)) throw InvalidArgument("noise_gen::ar1: rho must be in (-1, 1)");
  if (!(sigma_mm >= 0.0)) throw InvalidArgument("noise_gen::ar1: sigma_mm must be >= 0");
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(groups.size()));
  add_ar1(noise_streams(groups, times), rho, sigma_mm, rng, out);
  return out;
}

Eigen::VectorXd pink(const std::vector<std::string>& groups, const std::vector<double>& times,
                     double sigma_mm, std::uint64_t seed) {
  if (!(sigma_mm >= 0.0)) throw InvalidArgument("noise_gen::pink: sigma_mm must be >= 0");
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(groups.size()));
  const auto streams = noise_streams(groups, times);
  // Four equal-variance terms: the total marginal variance is sigma^2.
  for (double tau : {1.0, 10.0, 100.0, 1000.0})
    add_ar1(streams, std::exp(-1.0 / tau), sigma_mm / 2.0, rng, out);
  return out;
}

Eigen::VectorXd thermal_wander(const std::vector<double>& times, double amplitude_mm,
                               double period_s, std::uint64_t seed) {
  if (!(period_s > 0.0)) throw InvalidArgument("noise_gen::thermal_wander: period_s must be > 0");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double per[3], ph[3];
  for (int i = 0; i < 3; ++i) per[i] = period_s * (1.0 + 2.0 * U(rng)), ph[i] = 2.0 * M_PI * U(rng);
  Eigen::VectorXd out(static_cast<Eigen::Index>(times.size()));
  // Three sines of RMS a/sqrt(3) each: RMS a in all.
  const double a = amplitude_mm * std::sqrt(2.0 / 3.0);
  for (std::size_t i = 0; i < times.size(); ++i) {
    double v = 0.0;
    for (int k = 0; k < 3; ++k) v += a * std::sin(2.0 * M_PI * times[i] / per[k] + ph[k]);
    out[static_cast<Eigen::Index>(i)] = v;
  }
  return out;
}

Eigen::VectorXd probe_zero_wander(const std::vector<std::string>& groups,
                                  const std::vector<double>& times, double step_mm,
                                  std::uint64_t seed) {
  if (!(step_mm >= 0.0)) throw InvalidArgument("noise_gen::probe_zero_wander: step_mm must be >= 0");
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, step_mm);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(groups.size()));
  for (const auto& s : noise_streams(groups, times)) {
    double z = 0.0;
    for (std::size_t t = 0; t < s.size(); ++t) {
      if (t > 0) z += N(rng);
      out[s[t]] = z;
    }
  }
  return out;
}

}  // namespace noise_gen

}  // namespace rotacal
