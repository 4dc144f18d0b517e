// SPDX-License-Identifier: BSD-3-Clause
// The fits of the circular-test diagnosis: whitening by the noise model, least squares over the
// runs' baselines block by block (GLS), and the noise of the residuals.
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "../../diagnose/scoring.hpp"
#include "diagnosis_detail.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal::circular_detail {

using diagnosis_detail::orthonormal_basis;
using diagnosis_detail::solve_ls;

// Least squares against the model's columns M = [B | E] exploits the baseline's structure: B
// holds three columns per run that are zero outside that run's rows, and stay so whitened (the
// whitener works within each run's stream). The baseline is projected out run by run (an
// n_k x 3 QR each), then only the few effect columns E need a QR over all n rows: O(n e^2)
// instead of O(n (3 runs + e)^2), the same least-squares solution and span (Frisch-Waugh).
//
// An effect column that the baseline absorbs leaves a remainder of rounding size; the QR would
// scale it back up to unit norm and take it for a direction, so a remainder below 1e-9 of the
// column's norm (the rank threshold of solve_ls / orthonormal_basis) is set to zero.
void drop_absorbed(Eigen::MatrixXd& E, const Eigen::VectorXd& norm_before) {
  for (Eigen::Index j = 0; j < E.cols(); ++j)
    if (!(E.col(j).norm() > 1e-9 * norm_before[j])) E.col(j).setZero();
}

// Per-run orthonormal bases of the baseline columns of (whitened) M, rows by `first`/`count`.
std::vector<Eigen::MatrixXd> baseline_bases(const std::vector<Eigen::Index>& first,
                                            const std::vector<Eigen::Index>& count,
                                            const Eigen::MatrixXd& M) {
  ROTACAL_ASSERT(M.cols() >= static_cast<Eigen::Index>(3 * first.size()));
  std::vector<Eigen::MatrixXd> q(first.size());
  for (std::size_t k = 0; k < first.size(); ++k)
    q[k] = orthonormal_basis(M.block(first[k], static_cast<Eigen::Index>(3 * k), count[k], 3));
  return q;
}

const Whitening::Baseline& Whitening::baseline(const Rows& R,
                                               const Eigen::Ref<const Eigen::MatrixXd>& B) const {
  if (baseline_.version != version) {
    baseline_.Bw = (*this)(Eigen::MatrixXd(B));
    baseline_.qb = baseline_bases(R.run_first, R.run_count, baseline_.Bw);
    baseline_.version = version;
  }
  return baseline_;
}

void remove_baseline(const std::vector<Eigen::MatrixXd>& qb, const std::vector<Eigen::Index>& first,
                     const std::vector<Eigen::Index>& count, Eigen::MatrixXd& X) {
  // An empty X has no storage: a row block of it at a non-zero offset is pointer arithmetic on
  // null, undefined behaviour (clang's UBSan, test_circular_diagnosis).
  if (X.size() == 0) return;
  for (std::size_t k = 0; k < qb.size(); ++k) {
    auto block = X.middleRows(first[k], count[k]);
    block -= qb[k] * (qb[k].transpose() * block);
  }
}

// Least-squares coefficients of y on [B | E] (both already whitened; qb: B's per-run bases),
// rows of run k at [first[k], first[k] + count[k]).
Eigen::VectorXd block_solve(const std::vector<Eigen::Index>& first,
                            const std::vector<Eigen::Index>& count, const Eigen::MatrixXd& B,
                            const std::vector<Eigen::MatrixXd>& qb, const Eigen::MatrixXd& E,
                            const Eigen::VectorXd& y) {
  const Eigen::Index nb = B.cols(), ne = E.cols();
  Eigen::VectorXd beta(nb + ne);
  Eigen::VectorXd r = y;
  if (ne > 0) {
    Eigen::MatrixXd Ep = E;
    const Eigen::VectorXd norms = Ep.colwise().norm().transpose();
    Eigen::MatrixXd yp = y;
    remove_baseline(qb, first, count, Ep);
    remove_baseline(qb, first, count, yp);
    drop_absorbed(Ep, norms);
    beta.tail(ne) = solve_ls(Ep, yp.col(0));
    r -= E * beta.tail(ne);
  }
  for (std::size_t k = 0; k < first.size(); ++k)
    beta.segment(static_cast<Eigen::Index>(3 * k), 3) =
        solve_ls(B.block(first[k], static_cast<Eigen::Index>(3 * k), count[k], 3),
                 r.segment(first[k], count[k]));
  return beta;
}

// The same for M = [B | E] in one matrix.
Eigen::VectorXd block_solve(const std::vector<Eigen::Index>& first,
                            const std::vector<Eigen::Index>& count, const Eigen::MatrixXd& M,
                            const Eigen::VectorXd& y) {
  const Eigen::Index nb = static_cast<Eigen::Index>(3 * first.size());
  return block_solve(first, count, M.leftCols(nb), baseline_bases(first, count, M),
                     M.rightCols(M.cols() - nb), y);
}

ModelBasis::ModelBasis(const Rows& R, const Eigen::MatrixXd& Mw)
    : first_(&R.run_first),
      count_(&R.run_count),
      qb_(baseline_bases(R.run_first, R.run_count, Mw)) {
  const Eigen::Index nb = static_cast<Eigen::Index>(3 * R.runs);
  Eigen::MatrixXd E = Mw.rightCols(Mw.cols() - nb);
  const Eigen::VectorXd norms = E.colwise().norm().transpose();
  remove_baseline(qb_, *first_, *count_, E);
  drop_absorbed(E, norms);
  qe_ = orthonormal_basis(E);
}

int ModelBasis::rank() const {
  Eigen::Index r = qe_.cols();
  for (const Eigen::MatrixXd& q : qb_) r += q.cols();
  return static_cast<int>(r);
}

Eigen::MatrixXd ModelBasis::project_out(Eigen::MatrixXd X) const {
  remove_baseline(qb_, *first_, *count_, X);
  if (qe_.cols() > 0) X -= qe_ * (qe_.transpose() * X);
  return X;
}

CompressedFit::CompressedFit(const Rows& R, const Eigen::MatrixXd& Mw, const Eigen::VectorXd& yw)
    : nb_(static_cast<Eigen::Index>(3 * R.runs)) {
  const std::vector<Eigen::MatrixXd> qb = baseline_bases(R.run_first, R.run_count, Mw);
  const Eigen::Index e = Mw.cols() - nb_;
  Eigen::MatrixXd X(Mw.rows(), e + 1);
  X.leftCols(e) = Mw.rightCols(e);
  X.col(e) = yw;
  const Eigen::VectorXd norms = X.colwise().norm().transpose();
  remove_baseline(qb, R.run_first, R.run_count, X);
  Eigen::MatrixXd E = X.leftCols(e);
  drop_absorbed(E, norms.head(e));
  X.leftCols(e) = E;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
  const Eigen::Index rows = std::min<Eigen::Index>(X.rows(), e + 1);
  rf_ = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
}

double CompressedFit::rss_without(Eigen::Index from, Eigen::Index count) const {
  const Eigen::Index e = rf_.cols() - 1;
  ROTACAL_ASSERT(from >= nb_ && from + count <= nb_ + e);
  Eigen::MatrixXd S(rf_.rows(), e - count);
  Eigen::Index c = 0;
  for (Eigen::Index j = 0; j < e; ++j)
    if (j < from - nb_ || j >= from - nb_ + count) S.col(c++) = rf_.col(j);
  const Eigen::VectorXd ry = rf_.col(e);
  if (S.cols() == 0) return ry.squaredNorm();
  return (S * solve_ls(S, ry) - ry).squaredNorm();
}

// M = [B | E], B the baseline (whitened once per whitening: Whitening::baseline).
Gls gls(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y, const Whitening& W) {
  Gls g;
  const Eigen::Index nb = static_cast<Eigen::Index>(3 * R.runs), ne = M.cols() - nb;
  const Whitening::Baseline& base = W.baseline(R, M.leftCols(nb));
  const Eigen::MatrixXd Ew = W(M.rightCols(ne));
  const Eigen::VectorXd yw = W(Eigen::MatrixXd(y)).col(0);
  g.beta = block_solve(R.run_first, R.run_count, base.Bw, base.qb, Ew, yw);
  g.r_w = yw - Ew * g.beta.tail(ne);
  for (std::size_t k = 0; k < R.runs; ++k) {
    const Eigen::Index c = static_cast<Eigen::Index>(3 * k);
    g.r_w.segment(R.run_first[k], R.run_count[k]) -=
        base.Bw.block(R.run_first[k], c, R.run_count[k], 3) * g.beta.segment(c, 3);
  }
  g.r_mm = y - M * g.beta;
  g.rss_w = g.r_w.squaredNorm();
  return g;
}

// Noise sigma (mm) from successive differences within each run: sigma^2 = sum (r_{i+1} -
// r_i)^2 / (2 (n - 1)). Smooth systematic errors barely move it (the rotary diagnosis' rule);
// correlated noise makes it smaller than the marginal sigma, so tests on it are lenient,
// which the AR steps after it correct.
double difference_sigma(const Rows& R, const Eigen::VectorXd& r) {
  double ss = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 1; i < R.n; ++i)
    if (R.run[i] == R.run[i - 1]) {
      const double d = r[static_cast<Eigen::Index>(i)] - r[static_cast<Eigen::Index>(i - 1)];
      ss += d * d;
      ++n;
    }
  return n ? std::sqrt(ss / (2.0 * static_cast<double>(n))) : 0.0;
}

NoiseModel noise_of(const Rows& R, const Eigen::VectorXd& r) {
  NoiseModelOptions o;
  o.pooled = true;
  o.pool_only_if_all_coloured = true;
  o.reml_random_walk = false;
  return estimate_noise_model(R.group, R.time, r, o);
}

double rms_um(const Eigen::VectorXd& r) { return diagnosis_detail::rms_um(r); }

}  // namespace rotacal::circular_detail
