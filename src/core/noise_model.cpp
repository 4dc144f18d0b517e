// SPDX-License-Identifier: BSD-3-Clause
// Residual noise model: per-stream AR(p) by Burg with BIC order selection. (The exact AR
// prewhitener and the stream covariances are ar_whitener.cpp, the seeded coloured-noise
// generators noise_generators.cpp.)
#include "rotacal/core/noise_model.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <sstream>

#include "levinson.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace noise_detail {

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

}  // namespace noise_detail

using noise_detail::levinson;

namespace {

// One order m of Burg's recursion on a segment's forward and backward prediction errors f, b:
// adds its sums of f_t b_{t-1} and f_t^2 + b_{t-1}^2 over t = m..n-1. Written on Eigen
// segments so that they vectorise: the diagnosis models the residual of every candidate.
void burg_sums(const Eigen::VectorXd& f, const Eigen::VectorXd& b, Eigen::Index m, double* num,
               double* den) {
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
  const Eigen::VectorXd bs =
      b.segment(m - 1, len);  // a copy: b_t is overwritten before b_{t+1} reads it
  b.segment(m, len) = bs - km * f.segment(m, len);
  f.segment(m, len) -= km * bs;
}

// Burg's recursion up to order P over one or more segments (one model for all: the sums run
// over every segment): reflection coefficients k_1..k_P and the prediction error variances
// v_0..v_P (v_0 = mean square of the readings).
void burg_pooled(std::vector<Eigen::VectorXd> f, int P, std::vector<double>* k,
                 std::vector<double>* v, std::size_t* n_total = nullptr) {
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
      throw InvalidArgument(std::string(where) + ": times[" + std::to_string(i) +
                            "] is not finite");
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
    if (!std::is_sorted(idx.begin(), idx.end(), earlier))
      std::stable_sort(idx.begin(), idx.end(), earlier);
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
      const double d =
          times[static_cast<std::size_t>(s[t])] - times[static_cast<std::size_t>(s[t - 1])];
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

NoiseModel estimate_noise_model(const NoiseStreamLayout& layout,
                                const Eigen::VectorXd& residuals_mm,
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
  // BIC over orders min_order..P of Burg's prediction error variances v_p for n readings.
  const auto choose = [&options](const std::vector<double>& v, std::size_t n) {
    const std::size_t lowest =
        std::min(static_cast<std::size_t>(std::max(options.min_order, 0)), v.size() - 1);
    int best = static_cast<int>(lowest);
    double best_bic = 0.0;
    const double ln_n = std::log(static_cast<double>(std::max<std::size_t>(n, 2)));
    for (std::size_t p = lowest; p < v.size(); ++p) {
      const double bic =
          static_cast<double>(n) * std::log(std::max(v[p], 1e-300)) + static_cast<double>(p) * ln_n;
      if (p == lowest || bic < best_bic) best = static_cast<int>(p), best_bic = bic;
    }
    return best;
  };
  // Pooled: the coefficients and order of each pool (every stream, or each session's).
  const auto pool_of = [&options, &sg](std::size_t s) {
    return options.pool_by_session ? sg[s].substr(0, sg[s].find(':')) : std::string();
  };
  std::map<std::string, std::pair<std::vector<double>, int>> pooled;
  if (options.pooled) {
    std::map<std::string, std::vector<Eigen::VectorXd>> members;
    for (std::size_t s = 0; s < streams.size(); ++s) members[pool_of(s)].push_back(xs[s]);
    for (auto& [key, x] : members) {
      std::size_t shortest = SIZE_MAX, total = 0;
      for (const auto& xi : x) shortest = std::min(shortest, static_cast<std::size_t>(xi.size()));
      const int P = std::min(options.max_order, static_cast<int>(shortest / 4));
      std::vector<double> k, v;
      burg_pooled(std::move(x), std::max(P, 0), &k, &v, &total);
      pooled[key] = {k, choose(v, total)};
    }
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
      k = pooled.at(pool_of(s)).first, best = pooled.at(pool_of(s)).second;
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
    S.effective_samples =
        std::min(static_cast<double>(n), static_cast<double>(n) / S.correlation_samples);
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

namespace {

// Stream S as AR(1) with coefficient phi, its marginal sigma kept.
void set_ar1(NoiseStream& S, double phi) {
  const double n = static_cast<double>(S.rows.size());
  S.reflection.assign(1, phi);
  S.ar.assign(1, phi);
  S.innovation_sigma_um = S.marginal_sigma_um * std::sqrt(1.0 - phi * phi);
  // AR(1): tau = s_e^2 / (s_x^2 (1 - phi)^2) = (1 + phi) / (1 - phi).
  S.correlation_samples = std::min((1.0 + phi) / (1.0 - phi), n);
  S.correlation_time_s = S.correlation_samples * S.sample_interval_s;
  S.effective_samples = std::min(n, n / S.correlation_samples);
}

// The model's pooled figures again from its streams.
void resum(NoiseModel& M) {
  double ss_innov = 0.0;
  M.correlation_samples = 1.0, M.correlation_time_s = 0.0, M.effective_samples = 0.0;
  M.max_order = 0;
  for (const NoiseStream& S : M.streams) {
    ss_innov += std::pow(S.innovation_sigma_um, 2) * static_cast<double>(S.rows.size());
    M.correlation_samples = std::max(M.correlation_samples, S.correlation_samples);
    M.correlation_time_s = std::max(M.correlation_time_s, S.correlation_time_s);
    M.effective_samples += S.effective_samples;
    M.max_order = std::max(M.max_order, S.order());
  }
  if (M.n) M.innovation_sigma_um = std::sqrt(ss_innov / static_cast<double>(M.n));
}

}  // namespace

NoiseModel with_mean_bias_corrected(const NoiseModel& model) {
  NoiseModel M = model;
  for (NoiseStream& S : M.streams) {
    const double n = static_cast<double>(S.rows.size());
    if (S.order() == 1 && S.random_walk_step_um == 0.0 && n > 0) {
      const double k = S.reflection[0];
      set_ar1(S, std::min(0.995, k + (1.0 + 3.0 * k) / n));
    }
  }
  resum(M);
  return M;
}

NoiseModel with_lag1(const NoiseModel& model, const std::vector<double>& phi) {
  if (phi.size() != model.streams.size())
    throw InvalidArgument("with_lag1: " + std::to_string(phi.size()) + " coefficients for " +
                          std::to_string(model.streams.size()) + " streams");
  NoiseModel M = model;
  for (std::size_t s = 0; s < phi.size(); ++s) {
    if (!(std::abs(phi[s]) < 1.0))
      throw InvalidArgument("with_lag1: phi[" + std::to_string(s) + "] must be in (-1, 1)");
    if (M.streams[s].random_walk_step_um != 0.0)
      throw InvalidArgument("with_lag1: stream " + std::to_string(s) + " has a random walk");
    set_ar1(M.streams[s], phi[s]);
  }
  resum(M);
  return M;
}

std::string NoiseModel::summary() const {
  std::ostringstream out;
  out.precision(3);
  if (white())
    out << "white";
  else {
    out << "AR(" << max_order << ")";
    // The coefficient of the largest stream, as the typical one.
    const NoiseStream* big = nullptr;
    for (const NoiseStream& s : streams)
      if (!big || s.rows.size() > big->rows.size()) big = &s;
    if (big && big->order() >= 1) out << ", phi_1 " << big->ar[0];
    if (random_walk_step_um > 0.0)
      out << " + random walk " << random_walk_step_um << " um per reading";
  }
  out << ", sigma " << sigma_um << " um (innovation " << innovation_sigma_um
      << " um), correlation time " << correlation_time_s << " s (" << correlation_samples
      << " samples), " << effective_samples << " effective samples of " << n;
  return out.str();
}

}  // namespace rotacal
