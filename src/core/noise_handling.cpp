// SPDX-License-Identifier: BSD-3-Clause
// Bootstrap bias factor of a noise model estimated from fit residuals (core/noise_handling.hpp).
#include "rotacal/core/noise_handling.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "rotacal/core/error.hpp"

namespace rotacal {

NoiseHandling noise_handling_from_string(const std::string& noise) {
  if (noise == "auto") return NoiseHandling::automatic;
  if (noise == "white") return NoiseHandling::white;
  throw InvalidArgument("noise: expected 'auto' or 'white', got '" + noise + "'");
}

Eigen::VectorXd draw_noise(const NoiseModel& model, std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.n));
  for (const NoiseStream& s : model.streams) {
    const std::size_t p = s.ar.size();
    const double se = s.innovation_sigma_um * 1e-3;
    // Stationary start: run the recursion for many correlation times before the first row.
    const std::size_t burn =
        p == 0 ? 0 : 200 + static_cast<std::size_t>(20.0 * s.correlation_samples);
    std::vector<double> hist(p, 0.0);  // hist[k]: x_{t-1-k}
    const std::size_t total = burn + s.rows.size();
    for (std::size_t t = 0; t < total; ++t) {
      double x = se * N(rng);
      for (std::size_t k = 0; k < p; ++k) x += s.ar[k] * hist[k];
      if (p > 0) {
        std::rotate(hist.rbegin(), hist.rbegin() + 1, hist.rend());
        hist[0] = x;
      }
      if (t >= burn) e[s.rows[t - burn]] = x;
    }
    // The random walk from the stream's first reading (its start is the stream's level).
    if (s.random_walk_step_um > 0.0) {
      const double q = s.random_walk_step_um * 1e-3;
      double z = 0.0;
      for (std::size_t t = 0; t < s.rows.size(); ++t) {
        if (t > 0) z += q * N(rng);
        e[s.rows[t]] += z;
      }
    }
  }
  return e;
}

double long_run_variance(const NoiseModel& model) {
  double v = 0.0;
  for (const NoiseStream& s : model.streams) {
    double sum_phi = 0.0;
    for (double p : s.ar) sum_phi += p;
    const double se = s.innovation_sigma_um * 1e-3;
    v += static_cast<double>(s.rows.size()) * se * se /
         std::max(1e-12, (1.0 - sum_phi) * (1.0 - sum_phi));
  }
  return v;
}

double noise_model_bias_factor(const NoiseModel& model, const std::vector<std::string>& groups,
                               const std::vector<double>& times,
                               const Eigen::MatrixXd& jacobian_free,
                               const NoiseModelOptions& options, int draws, std::uint64_t seed) {
  const Eigen::Index n = static_cast<Eigen::Index>(groups.size());
  if (times.size() != groups.size() || jacobian_free.rows() != n ||
      static_cast<Eigen::Index>(model.n) != n)
    throw InvalidArgument(
        "noise_model_bias_factor: groups, times, jacobian_free rows and model.n must agree (" +
        std::to_string(groups.size()) + ", " + std::to_string(times.size()) + ", " +
        std::to_string(jacobian_free.rows()) + ", " + std::to_string(model.n) + ")");
  if (draws < 1) throw InvalidArgument("noise_model_bias_factor: draws must be >= 1");
  const double target = long_run_variance(model);
  if (model.white() || !(target > 0.0)) return 1.0;
  // Column-pivoted QR: projection onto the fitted directions, robust to scaling of columns.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jacobian_free);
  const Eigen::Index rank = qr.rank();
  // The first rank columns of Q alone: the full n x n Q was 800 MB at 10,000 readings.
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(n, rank);
  qr.householderQ().applyThisOnTheLeft(Q);
  std::mt19937_64 rng(seed);
  Eigen::VectorXd e(n);
  double sum = 0.0;
  for (int d = 0; d < draws; ++d) {
    e = draw_noise(model, rng);
    const Eigen::VectorXd r = e - Q * (Q.transpose() * e);
    sum += long_run_variance(estimate_noise_model(groups, times, r, options));
  }
  const double mean = sum / draws;
  return mean > 0.0 ? std::max(1.0, target / mean) : 1.0;
}

namespace {

// An orthonormal basis of X's columns (rank-revealing QR, its default threshold), made once per
// REML: the criterion depends on X through its span alone (S exactly; ln|X^T V^-1 X| up to a
// constant, which moves no optimum), and the Gram route below needs columns of one scale (X's,
// in mm per parameter, differ by orders of magnitude, which its Gram matrix squares).
Eigen::MatrixXd span_basis(const Eigen::MatrixXd& X) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(X.rows(), qr.rank());
  qr.householderQ().applyThisOnTheLeft(Q);
  return Q;
}

// 1^T C 1 / tr C of a stream's covariance (stream_covariance: C_ij = g_|i-j| + q2 min(i, j)) in
// O(n): the dense C was n^2 doubles, 800 MB for a probe session of 10,000 touches.
double covariance_sum_over_trace(const NoiseStream& s) {
  const std::size_t n = s.rows.size();
  if (n == 0) return 1.0;
  const std::vector<double> g = ar_autocovariance(s, n);
  const double q2 = std::pow(s.random_walk_step_um * 1e-3, 2);
  const double nd = static_cast<double>(n);
  double sum = nd * g[0], trace = nd * g[0];
  for (std::size_t k = 1; k < n; ++k) sum += 2.0 * (nd - static_cast<double>(k)) * g[k];
  // sum_ij min(i, j) = sum_m m (2 (n - 1 - m) + 1); sum_i i = n (n - 1) / 2.
  for (std::size_t m = 1; m < n; ++m)
    sum += q2 * static_cast<double>(m) * (2.0 * (nd - 1.0 - static_cast<double>(m)) + 1.0);
  trace += q2 * nd * (nd - 1.0) / 2.0;
  return trace > 0.0 ? sum / trace : 1.0;
}

// The REML criterion of an AR(1) + random-walk model (estimate_noise_model_reml).
class RemlCriterion {
 public:
  RemlCriterion(const NoiseModel& start, const Eigen::VectorXd& y, const Eigen::MatrixXd& X)
      : start_(start), y_(y), X_(span_basis(X)), level_(start.streams.size(), 1.0) {}

  struct Value {
    double m2l = 0.0;    // -2 l, profiled over sigma^2, up to a constant
    double S = 0.0;      // whitened GLS residual sum of squares (sigma^2 = 1)
    Eigen::Index k = 0;  // rank of X
    Eigen::VectorXd e;   // whitened GLS residuals (with `residuals`)
  };

  Value operator()(double rho, double lambda, bool residuals = false) const {
    const Eigen::Index n = y_.size(), p = X_.cols();
    Eigen::MatrixXd A(n, p + 1);  // [X y], whitened stream by stream
    A << X_, y_;
    const double logdet_v = whiten(rho, lambda, A);
    Value v;
    if (!residuals && by_gram(A, v)) {
      v.m2l += logdet_v;
      return v;
    }
    // Factorised in place (A's columns are not needed whitened again): no n x p copy.
    Eigen::Ref<Eigen::MatrixXd> WX = A.leftCols(p);
    const Eigen::ColPivHouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(WX);
    v.k = qr.rank();
    Eigen::VectorXd c = qr.householderQ().adjoint() * A.col(p);
    v.S = c.tail(n - v.k).squaredNorm();
    double logdet_xvx = 0.0;
    for (Eigen::Index i = 0; i < v.k; ++i)
      logdet_xvx += 2.0 * std::log(std::abs(qr.matrixQR()(i, i)));
    const double dof = static_cast<double>(n - v.k);
    v.m2l = dof * std::log(std::max(v.S, 1e-300) / dof) + logdet_v + logdet_xvx;
    if (residuals) {
      c.head(v.k).setZero();
      v.e = qr.householderQ() * c;
    }
    return v;
  }

  std::vector<double>& level() { return level_; }

 private:
  // A's rows whitened stream by stream; returns ln |V|.
  double whiten(double rho, double lambda, Eigen::MatrixXd& A) const {
    // V_s / sigma^2 = a_s (rho^|i-j| + lambda min(i, j)), whitened by its Kalman innovations.
    // Streams of one length and level share their filter (the gains depend on nothing else;
    // every level is 1 until the levels' rounds, and a ballbar's tests have few lengths).
    double logdet_v = 0.0;
    std::vector<ArWalkFilter> filters;
    filters.reserve(start_.streams.size());
    std::vector<std::size_t> filter_of(start_.streams.size());
    for (std::size_t s = 0; s < start_.streams.size(); ++s) {
      const std::size_t n_s = start_.streams[s].rows.size();
      std::size_t f = 0;  // an earlier stream of the same length and level
      while (f < s && !(start_.streams[f].rows.size() == n_s && level_[f] == level_[s])) ++f;
      if (f < s) {
        filter_of[s] = filter_of[f];
      } else {
        filter_of[s] = filters.size();
        filters.emplace_back(n_s, level_[s], rho, level_[s] * lambda);
      }
      const ArWalkFilter& w = filters[filter_of[s]];
      logdet_v += w.log_det();
      w.apply(start_.streams[s].rows, A);
    }
    return logdet_v;
  }

  // S and ln |X^T V^-1 X| from the Cholesky factor of the whitened [X y]'s Gram matrix (a
  // matrix product, several times faster than the column-pivoted QR, which is unblocked).
  // False, for the QR instead, where a whitened column is nearly in the span of the ones
  // before it (the Gram matrix squares the condition number) or y nearly in X's.
  bool by_gram(const Eigen::MatrixXd& A, Value& v) const {
    const Eigen::Index p = A.cols() - 1;
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(p + 1, p + 1);
    G.selfadjointView<Eigen::Lower>().rankUpdate(A.transpose());
    const Eigen::LLT<Eigen::MatrixXd> llt(G);
    if (llt.info() != Eigen::Success) return false;
    const Eigen::MatrixXd& L = llt.matrixLLT();
    double logdet_xvx = 0.0;
    for (Eigen::Index i = 0; i <= p; ++i) {
      const double d2 = L(i, i) * L(i, i);
      if (!(d2 > kMinNewFraction * G(i, i))) return false;
      if (i < p) logdet_xvx += std::log(d2);
    }
    v.k = p;
    v.S = L(p, p) * L(p, p);
    const double dof = static_cast<double>(A.rows() - p);
    v.m2l = dof * std::log(v.S / dof) + logdet_xvx;
    return true;
  }
  // What a whitened column must keep of its squared norm beyond the span of the ones before
  // it for the Gram route: the rounding of S (relative: ~ eps / this) then stays far below the
  // optimiser's tolerance (1e-4 in -2 l over some 10^3 readings).
  static constexpr double kMinNewFraction = 1e-6;

  const NoiseModel& start_;
  const Eigen::VectorXd& y_;
  const Eigen::MatrixXd X_;  // span_basis of the caller's X
  std::vector<double> level_;
};

// Nelder-Mead in two dimensions (standard coefficients), `evals` evaluations at most, stopped
// when the simplex' values agree to `ftol`.
template <typename F>
std::array<double, 2> nelder_mead_2d(F f, std::array<double, 2> x0, std::array<double, 2> step,
                                     int evals, double ftol) {
  std::array<std::array<double, 2>, 3> x = {x0, x0, x0};
  x[1][0] += step[0];
  x[2][1] += step[1];
  std::array<double, 3> fx = {f(x[0]), f(x[1]), f(x[2])};
  int used = 3;
  const auto mix = [](const std::array<double, 2>& a, const std::array<double, 2>& b, double t) {
    return std::array<double, 2>{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
  };
  while (used < evals) {
    std::array<int, 3> o = {0, 1, 2};
    std::sort(o.begin(), o.end(), [&](int a, int b) {
      return fx[static_cast<std::size_t>(a)] < fx[static_cast<std::size_t>(b)];
    });
    const std::size_t b = static_cast<std::size_t>(o[0]), m = static_cast<std::size_t>(o[1]),
                      w = static_cast<std::size_t>(o[2]);
    if (fx[w] - fx[b] < ftol) break;
    const std::array<double, 2> c = mix(x[b], x[m], 0.5);
    const std::array<double, 2> r = mix(c, x[w], -1.0);
    const double fr = f(r);
    ++used;
    if (fr < fx[b]) {
      const std::array<double, 2> e = mix(c, x[w], -2.0);
      const double fe = f(e);
      ++used;
      if (fe < fr)
        x[w] = e, fx[w] = fe;
      else
        x[w] = r, fx[w] = fr;
    } else if (fr < fx[m]) {
      x[w] = r, fx[w] = fr;
    } else {
      const bool outside = fr < fx[w];
      const std::array<double, 2> k = mix(c, outside ? r : x[w], 0.5);
      const double fk = f(k);
      ++used;
      if (fk < std::min(fr, fx[w])) {
        x[w] = k, fx[w] = fk;
      } else {  // shrink towards the best
        for (std::size_t i : {m, w}) x[i] = mix(x[b], x[i], 0.5), fx[i] = f(x[i]);
        used += 2;
      }
    }
  }
  std::size_t best = 0;
  for (std::size_t i = 1; i < 3; ++i)
    if (fx[i] < fx[best]) best = i;
  return x[best];
}

}  // namespace

NoiseModel estimate_noise_model_reml(const NoiseModel& start, const Eigen::VectorXd& y,
                                     const Eigen::MatrixXd& X) {
  const Eigen::Index n = y.size();
  if (static_cast<Eigen::Index>(start.n) != n || X.rows() != n)
    throw InvalidArgument(
        "estimate_noise_model_reml: start.n, residuals and jacobian_free rows must agree (" +
        std::to_string(start.n) + ", " + std::to_string(n) + ", " + std::to_string(X.rows()) + ")");
  std::size_t covered = 0;
  for (const NoiseStream& s : start.streams) covered += s.rows.size();
  if (covered != start.n)
    throw InvalidArgument("estimate_noise_model_reml: start's streams do not cover its readings");
  RemlCriterion crit(start, y, X);
  // rho = 0.995 tanh(u) (|rho| < 0.995: beyond it the AR part is a walk itself),
  // lambda = exp(v) with v in [-18, 4] (e^-18: no walk; e^4: walk steps 7x the AR sigma).
  const auto rho_of = [](double u) { return 0.995 * std::tanh(u); };
  const auto lambda_of = [](double v) { return std::exp(std::min(4.0, std::max(-18.0, v))); };
  const auto f = [&](const std::array<double, 2>& x) {
    const double pen = std::max(0.0, x[1] - 4.0) + std::max(0.0, -18.0 - x[1]);  // keep v in range
    return crit(rho_of(x[0]), lambda_of(x[1])).m2l + 10.0 * pen * pen;
  };
  // Start: the largest stream's phi_1 (biased low, a start only) and a small walk.
  double phi1 = 0.0;
  std::size_t big = 0;
  for (const NoiseStream& s : start.streams)
    if (s.rows.size() > big && s.order() >= 1) big = s.rows.size(), phi1 = s.ar[0];
  std::array<double, 2> x = {std::atanh(std::max(-0.9, std::min(0.95, phi1)) / 0.995),
                             std::log(1e-3)};
  // Where the levels' steps and a second Nelder-Mead follow, the first optimum is only their
  // start, so it stops at 1e-2 in -2 l: a tenth of a standard deviation of (rho, ln lambda) on
  // the likelihood-ratio scale (one at 1), far below the levels' own uncertainty; the second
  // Nelder-Mead then takes -2 l to 1e-4 as before. First-stage evaluations 49 -> 34 a REML
  // (all 87 -> 72), no decision changed (bench/diagnosis_confusion.py, 208 AC-trt ballbar
  // sessions).
  const bool levels = start.streams.size() > 1;
  x = nelder_mead_2d(f, x, {0.5, 3.0}, 120, levels ? 1e-2 : 1e-4);
  // The streams' levels (dx, dy, dz probes may differ): two fixed-point steps at the first
  // optimum's (rho, lambda), then (rho, lambda) again. A Nelder-Mead between the two steps, as
  // before, moved rho by < 2e-3 and ln lambda by < 0.02 (9 REMLs of three 1/f-like ballbar
  // sessions) and cost some 40 of a REML's ~140 evaluations.
  if (levels) {
    for (int round = 0; round < 2; ++round) {
      const RemlCriterion::Value v = crit(rho_of(x[0]), lambda_of(x[1]), true);
      const double mean_sq = v.S / static_cast<double>(n);
      double log_mean = 0.0;
      std::vector<double>& a = crit.level();
      for (std::size_t s = 0; s < start.streams.size(); ++s) {
        double ss = 0.0;
        for (Eigen::Index r : start.streams[s].rows) ss += v.e[r] * v.e[r];
        a[s] *= std::max(1e-6, ss / static_cast<double>(start.streams[s].rows.size()) / mean_sq);
        log_mean += std::log(a[s]);
      }
      log_mean /= static_cast<double>(a.size());
      for (double& as : a) as /= std::exp(log_mean);
    }
    x = nelder_mead_2d(f, x, {0.2, 1.0}, 60, 1e-4);
  }
  const double rho = rho_of(x[0]);
  double lambda = lambda_of(x[1]);
  const RemlCriterion::Value v = crit(rho, lambda);
  const double sigma2 = v.S / static_cast<double>(n - v.k);  // REML: unbiased for sigma^2
  std::size_t longest = 0;
  for (const NoiseStream& s : start.streams) longest = std::max(longest, s.rows.size());
  if (lambda * static_cast<double>(longest) < 1e-3)
    lambda = 0.0;  // a walk under 0.1 % of the variance

  NoiseModel M;
  M.n = start.n;
  double ss_marg = 0.0, ss_innov = 0.0;
  for (std::size_t s = 0; s < start.streams.size(); ++s) {
    NoiseStream S = start.streams[s];
    const double var = sigma2 * crit.level()[s];
    const double ns = static_cast<double>(S.rows.size());
    S.ar = {rho};
    S.reflection = {rho};
    S.marginal_sigma_um = std::sqrt(var) * 1e3;
    S.innovation_sigma_um = S.marginal_sigma_um * std::sqrt(1.0 - rho * rho);
    S.random_walk_step_um = std::sqrt(lambda * var) * 1e3;
    // tau = 1^T V 1 / tr V: the AR definition (long-run over marginal variance) for a finite
    // stream, which a walk makes grow with n.
    S.correlation_samples = std::min(ns, std::max(1e-3, covariance_sum_over_trace(S)));
    S.correlation_time_s = S.correlation_samples * S.sample_interval_s;
    S.effective_samples = std::min(ns, ns / S.correlation_samples);
    ss_marg += var * ns;
    ss_innov += var * (1.0 - rho * rho) * ns;
    M.correlation_samples = std::max(M.correlation_samples, S.correlation_samples);
    M.correlation_time_s = std::max(M.correlation_time_s, S.correlation_time_s);
    M.effective_samples += S.effective_samples;
    M.random_walk_step_um = std::max(M.random_walk_step_um, S.random_walk_step_um);
    M.streams.push_back(std::move(S));
  }
  M.max_order = 1;
  if (M.n) {
    M.sigma_um = std::sqrt(ss_marg / static_cast<double>(M.n)) * 1e3;
    M.innovation_sigma_um = std::sqrt(ss_innov / static_cast<double>(M.n)) * 1e3;
  }
  return M;
}

}  // namespace rotacal
