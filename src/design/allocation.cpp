// SPDX-License-Identifier: BSD-3-Clause
// The design engine's allocation of runs among candidate measurements (design/allocation.hpp).
#include "rotacal/design/allocation.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

// The criterion on the determined parameters F only (the search's screening): the largest
// scale_j^2 [M^-1]_jj over the target positions in F, or infinity when M is singular.
struct Reduced {
  std::vector<Eigen::MatrixXd> A;    // candidates restricted to F
  std::vector<Eigen::Index> target;  // positions in F of the determinable target parameters
  std::vector<double> scale2;        // their scale^2

  // M^-1 of a positive definite M, by Cholesky of its diagonally scaled form; false if singular.
  static bool inverse(const Eigen::MatrixXd& M, Eigen::MatrixXd& out) {
    const Eigen::VectorXd d = M.diagonal();
    if (!(d.minCoeff() > 0.0)) return false;
    const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
    const Eigen::LLT<Eigen::MatrixXd> llt(s.asDiagonal() * M * s.asDiagonal());
    if (llt.info() != Eigen::Success) return false;
    const Eigen::VectorXd diag = llt.matrixL().toDenseMatrix().diagonal();
    if (!(diag.minCoeff() > 1e-7 * diag.maxCoeff())) return false;
    out =
        s.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(M.rows(), M.cols())) * s.asDiagonal();
    return true;
  }
  // The derivative d_k of the smooth maximum (sum_j v_j^64)^(1/64) along each candidate at M:
  // how much one more run of it lowers the smooth maximum; empty when M is singular.
  Eigen::VectorXd derivative(const Eigen::MatrixXd& M) const {
    Eigen::MatrixXd inv;
    if (!inverse(M, inv)) return {};
    double vmax = 0.0;
    for (std::size_t t = 0; t < target.size(); ++t)
      vmax = std::max(vmax, scale2[t] * inv(target[t], target[t]));
    Eigen::VectorXd L = Eigen::VectorXd::Zero(M.rows());
    for (std::size_t t = 0; t < target.size(); ++t)
      L[target[t]] = scale2[t] * std::pow(scale2[t] * inv(target[t], target[t]) / vmax, 63.0);
    const Eigen::MatrixXd B = inv * L.asDiagonal() * inv;
    Eigen::VectorXd d(static_cast<Eigen::Index>(A.size()));
    for (std::size_t k = 0; k < A.size(); ++k)
      d[static_cast<Eigen::Index>(k)] = B.cwiseProduct(A[k]).sum();
    return d;
  }
  double worst(const Eigen::MatrixXd& M) const {
    Eigen::MatrixXd inv;
    if (!inverse(M, inv)) return std::numeric_limits<double>::infinity();
    double w = 0.0;
    for (std::size_t t = 0; t < target.size(); ++t)
      w = std::max(w, scale2[t] * inv(target[t], target[t]));
    return w;
  }
};

// The continuous minimax design: weights w over the candidates (summing to 1) minimising the
// largest scaled variance v_j = s_j^2 [M(w)^-1]_jj, M(w) = sum w_k A_k, by the file comment's
// Lagrangian: for weights lam over the target, the lam-weighted A-optimal w by the
// multiplicative algorithm, then lam moved towards the largest variances; the w with the smallest
// max v is kept. Each A_k enters as a factor F_k (A_k = F_k F_k^T, its eigenvectors times the
// square roots of its eigenvalues), so that every derivative is one matrix product:
// d_k = |W F_k|_F^2, W = L^(1/2) M^-1 restricted to the target rows.
Eigen::VectorXd continuous_design(const Reduced& R) {
  const std::size_t C = R.A.size();
  const Eigen::Index q = R.A.front().rows(), T = static_cast<Eigen::Index>(R.target.size());
  std::vector<Eigen::Index> first(C + 1, 0);
  std::vector<Eigen::MatrixXd> factors(C);
  for (std::size_t k = 0; k < C; ++k) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(R.A[k]);
    const Eigen::VectorXd& ev = es.eigenvalues();
    Eigen::Index r = 0;
    factors[k].resize(q, q);
    for (Eigen::Index i = 0; i < q; ++i)
      if (ev[i] > 1e-12 * std::max(ev.maxCoeff(), 0.0) && ev[i] > 0.0)
        factors[k].col(r++) = es.eigenvectors().col(i) * std::sqrt(ev[i]);
    factors[k].conservativeResize(q, r);
    first[k + 1] = first[k] + r;
  }
  Eigen::MatrixXd F(q, first[C]);
  for (std::size_t k = 0; k < C; ++k) F.middleCols(first[k], first[k + 1] - first[k]) = factors[k];
  Eigen::VectorXd w =
      Eigen::VectorXd::Constant(static_cast<Eigen::Index>(C), 1.0 / static_cast<double>(C));
  Eigen::VectorXd lam = Eigen::VectorXd::Constant(T, 1.0 / static_cast<double>(T)), best_w = w;
  double best = std::numeric_limits<double>::infinity();
  Eigen::VectorXd root(first[C]), d(static_cast<Eigen::Index>(C)), v(T);
  Eigen::MatrixXd inv, W(T, q);
  const auto target = [&](Eigen::Index t) { return R.target[static_cast<std::size_t>(t)]; };
  const auto scale2 = [&](Eigen::Index t) { return R.scale2[static_cast<std::size_t>(t)]; };
  const auto information = [&]() {
    for (std::size_t k = 0; k < C; ++k)
      root.segment(first[k], first[k + 1] - first[k])
          .setConstant(std::sqrt(w[static_cast<Eigen::Index>(k)]));
    const Eigen::MatrixXd Fw = F * root.asDiagonal();
    return Reduced::inverse(Fw * Fw.transpose(), inv);
  };
  for (int outer = 0; outer < 40; ++outer) {
    for (int it = 0; it < 10; ++it) {
      if (!information()) return best < std::numeric_limits<double>::infinity() ? best_w : w;
      for (Eigen::Index t = 0; t < T; ++t)
        W.row(t) = inv.row(target(t)) * std::sqrt(lam[t] * scale2(t));
      const Eigen::RowVectorXd col = (W * F).colwise().squaredNorm();
      for (std::size_t k = 0; k < C; ++k)
        d[static_cast<Eigen::Index>(k)] = col.segment(first[k], first[k + 1] - first[k]).sum();
      const double mean = w.dot(d);
      if (!(mean > 0.0)) return w;
      w = w.cwiseProduct((d / mean).cwiseMax(0.0).cwiseSqrt());
      w /= w.sum();
    }
    if (!information()) break;
    for (Eigen::Index t = 0; t < T; ++t) v[t] = scale2(t) * inv(target(t), target(t));
    if (v.maxCoeff() < best) best = v.maxCoeff(), best_w = w;
    lam = lam.cwiseProduct((2.0 * (v / v.maxCoeff()).array() - 2.0).exp().matrix());
    lam /= lam.sum();
  }
  return best_w;
}

// Pukelsheim and Rieder's efficient rounding of weights w to n runs.
std::vector<int> efficient_rounding(const Eigen::VectorXd& w, int n) {
  const std::size_t C = static_cast<std::size_t>(w.size());
  std::vector<std::size_t> support;
  for (std::size_t k = 0; k < C; ++k)
    if (w[static_cast<Eigen::Index>(k)] > 1e-4) support.push_back(k);
  std::sort(support.begin(), support.end(), [&](std::size_t a, std::size_t b) {
    return w[static_cast<Eigen::Index>(a)] > w[static_cast<Eigen::Index>(b)];
  });
  if (static_cast<int>(support.size()) > n) support.resize(static_cast<std::size_t>(n));
  double total = 0.0;
  for (std::size_t k : support) total += w[static_cast<Eigen::Index>(k)];
  std::vector<int> counts(C, 0);
  const double l = static_cast<double>(support.size());
  for (std::size_t k : support)
    counts[k] = std::max(
        1, static_cast<int>(std::ceil((n - l / 2.0) * w[static_cast<Eigen::Index>(k)] / total)));
  const auto weight = [&](std::size_t k) { return w[static_cast<Eigen::Index>(k)] / total; };
  int sum = std::accumulate(counts.begin(), counts.end(), 0);
  while (sum < n) {
    std::size_t best = support.front();
    for (std::size_t k : support)
      if (counts[k] / weight(k) < counts[best] / weight(best)) best = k;
    ++counts[best], ++sum;
  }
  while (sum > n) {
    std::size_t best = support.front();
    for (std::size_t k : support)
      if (counts[k] > 1 &&
          (counts[best] <= 1 || (counts[k] - 1) / weight(k) > (counts[best] - 1) / weight(best)))
        best = k;
    --counts[best], --sum;
  }
  return counts;
}

}  // namespace

DesignUncertainty design_uncertainty(const Inverted& inv, const ParameterBlock& target,
                                     const Eigen::VectorXd& scale,
                                     const std::vector<bool>& required) {
  DesignUncertainty out;
  out.feasible = true;
  out.worst = 0.0;
  for (Eigen::Index j = 0; j < target.size; ++j) {
    const Eigen::Index i = target.offset + j;
    if (!inv.determined[static_cast<std::size_t>(i)]) {
      if (required[static_cast<std::size_t>(j)]) out.feasible = false;
      continue;
    }
    const double u = scale[j] * inv.sigma[i];
    if (u > out.worst) out.worst = u, out.worst_index = i;
  }
  if (!out.feasible) out.worst = std::numeric_limits<double>::infinity();
  return out;
}

Allocation allocate_runs(const AllocationProblem& P) {
  const std::size_t C = P.candidates.size();
  if (C == 0) throw InvalidArgument("allocate_runs: no candidate");
  if (P.runs < 1) throw InvalidArgument("allocate_runs: runs must be >= 1");
  const Eigen::Index p = P.candidates.front().rows();
  for (const Eigen::MatrixXd& A : P.candidates)
    if (A.rows() != p || A.cols() != p)
      throw InvalidArgument("allocate_runs: candidates of different sizes");
  if (P.scale.size() != P.target.size || P.plausible.size() < p || P.target.end() > p)
    throw InvalidArgument("allocate_runs: scale, plausible or target do not fit the candidates");
  // What all candidates together determine: the criterion's parameters.
  Eigen::MatrixXd all = Eigen::MatrixXd::Zero(p, p);
  for (const Eigen::MatrixXd& A : P.candidates)
    all += A * (static_cast<double>(P.runs) / static_cast<double>(C));
  const Inverted every = invert_information(all, P.plausible.head(p), P.white);
  Allocation out;
  std::vector<Eigen::Index> F;
  for (Eigen::Index j = 0; j < p; ++j)
    if (every.determined[static_cast<std::size_t>(j)]) F.push_back(j);
  for (Eigen::Index j = 0; j < P.target.size; ++j)
    out.determinable.push_back(every.determined[static_cast<std::size_t>(P.target.offset + j)]);
  Reduced R;
  for (const Eigen::MatrixXd& A : P.candidates) R.A.push_back(A(F, F));
  for (Eigen::Index a = 0; a < static_cast<Eigen::Index>(F.size()); ++a)
    if (P.target.contains(F[static_cast<std::size_t>(a)]))
      R.target.push_back(a), R.scale2.push_back(std::pow(
                                 P.scale[F[static_cast<std::size_t>(a)] - P.target.offset], 2));

  out.counts = efficient_rounding(continuous_design(R), P.runs);
  const auto information = [&](const std::vector<int>& n) {
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(p, p);
    for (std::size_t k = 0; k < C; ++k)
      if (n[k]) M += n[k] * P.candidates[k];
    return M;
  };
  const auto judge = [&](const std::vector<int>& n, Inverted& inv) {
    inv = invert_information(information(n), P.plausible.head(p), P.white);
    return design_uncertainty(inv, P.target, P.scale, out.determinable);
  };
  out.uncertainty = judge(out.counts, out.inverted);

  // Exchange: the move of one run from a candidate in use to another that the screening on F
  // finds best, kept while the engine's largest expanded uncertainty decreases. Among more than
  // kMany candidates only the kReceivers with the largest derivative of the criterion are tried
  // as the receiving one (the others lower it less to first order): the touch probe's single
  // touches are thousands, and every pair would cost seconds per move.
  constexpr std::size_t kMany = 400, kReceivers = 16;
  Eigen::MatrixXd M = information(out.counts)(F, F);
  for (int move = 0; move < 4 * P.runs; ++move) {
    const double now = R.worst(M);
    double best = now;
    std::size_t from = C, to = C;
    std::vector<std::size_t> receivers(C);
    std::iota(receivers.begin(), receivers.end(), std::size_t{0});
    if (C > kMany) {
      const Eigen::VectorXd d = R.derivative(M);
      if (d.size() == 0) break;
      const auto larger = [&](std::size_t a, std::size_t b) {
        return d[static_cast<Eigen::Index>(a)] > d[static_cast<Eigen::Index>(b)];
      };
      std::partial_sort(receivers.begin(), receivers.begin() + kReceivers, receivers.end(), larger);
      receivers.resize(kReceivers);
    }
    for (std::size_t a = 0; a < C; ++a) {
      if (!out.counts[a]) continue;
      const Eigen::MatrixXd Ma = M - R.A[a];
      for (std::size_t b : receivers) {
        if (b == a) continue;
        const double v = R.worst(Ma + R.A[b]);
        if (v < best) best = v, from = a, to = b;
      }
    }
    if (from == C || !(best < now * (1.0 - 1e-9))) break;
    std::vector<int> trial = out.counts;
    --trial[from], ++trial[to];
    Inverted inv;
    const DesignUncertainty u = judge(trial, inv);
    if (!(u.feasible && u.worst < out.uncertainty.worst)) break;
    out.counts = std::move(trial);
    out.inverted = std::move(inv);
    out.uncertainty = u;
    M += R.A[to] - R.A[from];
  }
  return out;
}

}  // namespace rotacal
