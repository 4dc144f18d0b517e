// The design engine's allocation of runs among candidate measurements (design/allocation.hpp).
#include "rotacal/design/allocation.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

// The criterion on the determined parameters F only (the search's screening): the largest
// scale_j^2 [M^-1]_jj over the target positions in F, or infinity when M is singular.
struct Reduced {
  std::vector<Eigen::MatrixXd> A;       // candidates restricted to F
  std::vector<Eigen::Index> target;     // positions in F of the determinable target parameters
  std::vector<double> scale2;           // their scale^2

  // M^-1 of a positive definite M, by Cholesky of its diagonally scaled form; false if singular.
  static bool inverse(const Eigen::MatrixXd& M, Eigen::MatrixXd& out) {
    const Eigen::VectorXd d = M.diagonal();
    if (!(d.minCoeff() > 0.0)) return false;
    const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
    const Eigen::LLT<Eigen::MatrixXd> llt(s.asDiagonal() * M * s.asDiagonal());
    if (llt.info() != Eigen::Success) return false;
    const Eigen::VectorXd diag = llt.matrixL().toDenseMatrix().diagonal();
    if (!(diag.minCoeff() > 1e-7 * diag.maxCoeff())) return false;
    out = s.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(M.rows(), M.cols())) * s.asDiagonal();
    return true;
  }
  double worst(const Eigen::MatrixXd& M) const {
    Eigen::MatrixXd inv;
    if (!inverse(M, inv)) return std::numeric_limits<double>::infinity();
    double w = 0.0;
    for (std::size_t t = 0; t < target.size(); ++t) w = std::max(w, scale2[t] * inv(target[t], target[t]));
    return w;
  }
};

// The continuous design: weights over the candidates (summing to 1) minimising the smooth
// maximum of the scaled variances, by the multiplicative algorithm of the file comment.
Eigen::VectorXd continuous_design(const Reduced& R) {
  const std::size_t C = R.A.size();
  Eigen::VectorXd w = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(C), 1.0 / static_cast<double>(C));
  const Eigen::Index q = R.A.front().rows();
  for (const double p : {1.0, 4.0, 16.0, 64.0}) {
    for (int it = 0; it < 150; ++it) {
      Eigen::MatrixXd M = Eigen::MatrixXd::Zero(q, q), inv;
      for (std::size_t k = 0; k < C; ++k) M += w[static_cast<Eigen::Index>(k)] * R.A[k];
      if (!Reduced::inverse(M, inv)) return w;
      double vmax = 0.0;
      for (std::size_t t = 0; t < R.target.size(); ++t) vmax = std::max(vmax, R.scale2[t] * inv(R.target[t], R.target[t]));
      Eigen::VectorXd L = Eigen::VectorXd::Zero(q);
      for (std::size_t t = 0; t < R.target.size(); ++t)
        L[R.target[t]] = R.scale2[t] * std::pow(R.scale2[t] * inv(R.target[t], R.target[t]) / vmax, p - 1.0);
      const Eigen::MatrixXd B = inv * L.asDiagonal() * inv;
      Eigen::VectorXd d(static_cast<Eigen::Index>(C));
      for (std::size_t k = 0; k < C; ++k) d[static_cast<Eigen::Index>(k)] = B.cwiseProduct(R.A[k]).sum();
      const double mean = w.dot(d);
      if (!(mean > 0.0)) return w;
      w = w.cwiseProduct((d / mean).cwiseMax(0.0).cwiseSqrt());
      w /= w.sum();
    }
  }
  return w;
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
    counts[k] = std::max(1, static_cast<int>(std::ceil((n - l / 2.0) * w[static_cast<Eigen::Index>(k)] / total)));
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
      if (counts[k] > 1 && (counts[best] <= 1 || (counts[k] - 1) / weight(k) > (counts[best] - 1) / weight(best)))
        best = k;
    --counts[best], --sum;
  }
  return counts;
}

}  // namespace

DesignUncertainty design_uncertainty(const Inverted& inv, const ParameterBlock& target, const Eigen::VectorXd& scale,
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
    if (A.rows() != p || A.cols() != p) throw InvalidArgument("allocate_runs: candidates of different sizes");
  if (P.scale.size() != P.target.size || P.plausible.size() < p || P.target.end() > p)
    throw InvalidArgument("allocate_runs: scale, plausible or target do not fit the candidates");
  // What all candidates together determine: the criterion's parameters.
  Eigen::MatrixXd all = Eigen::MatrixXd::Zero(p, p);
  for (const Eigen::MatrixXd& A : P.candidates) all += A * (static_cast<double>(P.runs) / static_cast<double>(C));
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
      R.target.push_back(a), R.scale2.push_back(std::pow(P.scale[F[static_cast<std::size_t>(a)] - P.target.offset], 2));

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
  // finds best, kept while the engine's largest expanded uncertainty decreases.
  Eigen::MatrixXd M = information(out.counts)(F, F);
  for (int move = 0; move < 4 * P.runs; ++move) {
    const double now = R.worst(M);
    double best = now;
    std::size_t from = C, to = C;
    for (std::size_t a = 0; a < C; ++a) {
      if (!out.counts[a]) continue;
      const Eigen::MatrixXd Ma = M - R.A[a];
      for (std::size_t b = 0; b < C; ++b) {
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
