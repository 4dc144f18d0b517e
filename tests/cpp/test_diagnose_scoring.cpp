// SPDX-License-Identifier: BSD-3-Clause
// The one scorer and cross-validation of src/diagnose/scoring.hpp, which the engine and the
// circular-test diagnosis share: score_columns against an independent dense least-squares fit,
// its visibility decisions, and the blocked CV RMS against means worked out by hand.
#include <Eigen/QR>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "../../src/diagnose/scoring.hpp"
#include "rotacal/core/stats.hpp"

using namespace rotacal;
using namespace rotacal::diagnosis_detail;

namespace {

Eigen::MatrixXd gaussian(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::MatrixXd M(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) M(i, j) = N(rng);
  return M;
}

// Residual of y after the least-squares fit on X (Householder QR, independent of the scorer).
Eigen::VectorXd ls_residual(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  return y - X * X.colPivHouseholderQr().solve(y);
}

// The Gram quantities of candidate columns Jc (whitened) against model columns Jf, residuals r0
// of the model, per plausible size m: formed from an explicit projection.
CandidateGrams grams_of(const Eigen::MatrixXd& Jf, const Eigen::MatrixXd& Jc,
                        const Eigen::VectorXd& r0, const Eigen::VectorXd& m) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Jf);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(Jf.rows(), Jf.cols());
  const Eigen::MatrixXd P = (Jc - Q * (Q.transpose() * Jc)) * m.asDiagonal();
  CandidateGrams g;
  g.raw = m.asDiagonal() * Jc.transpose() * Jc * m.asDiagonal();
  g.perp = P.transpose() * P;
  g.perp_r = P.transpose() * r0;
  g.rr = r0.squaredNorm();
  g.n = static_cast<double>(r0.size());
  return g;
}

}  // namespace

TEST_CASE("score_columns refits as the joint least squares, nonlinear parameters counted",
          "[scoring]") {
  std::mt19937 rng(3);
  const Eigen::Index n = 400;
  const Eigen::MatrixXd Jf = gaussian(n, 3, rng);
  const Eigen::MatrixXd Jc = gaussian(n, 2, rng);
  // Unit-variance residuals with a weak candidate signal (F about 5), so p is a number to test.
  const Eigen::VectorXd y = gaussian(n, 1, rng).col(0) + Jc * Eigen::Vector2d(0.12, -0.1);
  const Eigen::VectorXd r0 = ls_residual(Jf, y);
  const Eigen::Vector2d m(0.5, 2.0);  // plausible sizes: only visibility depends on them
  const int nonlinear = 1;
  const ColumnScore s = score_columns(m, grams_of(Jf, Jc, r0, m), 3, nonlinear, 25.0);

  Eigen::MatrixXd X(n, 5);
  X << Jf, Jc;
  const Eigen::VectorXd beta = X.colPivHouseholderQr().solve(y);
  const double rss1 = (y - X * beta).squaredNorm(), rss0 = r0.squaredNorm();
  REQUIRE(s.decided);
  REQUIRE(s.visible);
  CHECK(s.k == 2);
  CHECK(s.rss1 == Approx(rss1).epsilon(1e-10));
  CHECK(s.params[0] == Approx(beta[3]).epsilon(1e-8));
  CHECK(s.params[1] == Approx(beta[4]).epsilon(1e-8));
  const double N = static_cast<double>(n);
  CHECK(s.delta_bic == Approx(N * std::log(rss1 / rss0) + 3 * std::log(N)).epsilon(1e-10));
  // F on (k, n - free - k - nonlinear) degrees of freedom.
  const double dof = N - 3 - 2 - nonlinear;
  const double F = ((rss0 - rss1) / 2) / (rss1 / dof);
  CHECK(F > 2.0);
  CHECK(s.f_pvalue == Approx(stats::f_sf(F, 2, dof)).epsilon(1e-10));
  CHECK(s.f_pvalue < 0.2);
}

TEST_CASE("score_columns: directions below the threshold, absorbed and undecided candidates",
          "[scoring]") {
  std::mt19937 rng(5);
  const Eigen::Index n = 300;
  const Eigen::MatrixXd Jf = gaussian(n, 3, rng);
  const Eigen::VectorXd r0 = ls_residual(Jf, gaussian(n, 1, rng).col(0));
  const Eigen::Vector2d m(1.0, 1.0);

  // Columns of norm ~17 and ~0.17: chi-square changes ~300 and ~0.03 at plausible sizes.
  Eigen::MatrixXd Jc = gaussian(n, 2, rng);
  Jc.col(1) *= 0.01;
  const ColumnScore one = score_columns(m, grams_of(Jf, Jc, r0, m), 3, 0, 25.0);
  CHECK(one.visible);
  CHECK(one.k == 1);

  // Inside the model's span: visible alone, nothing once the model is projected out.
  const Eigen::MatrixXd inside = Jf * gaussian(3, 2, rng);
  const ColumnScore absorbed = score_columns(m, grams_of(Jf, inside, r0, m), 3, 0, 25.0);
  CHECK_FALSE(absorbed.visible);
  CHECK(absorbed.absorbed);

  // Too small to see at all.
  const ColumnScore small =
      score_columns(m, grams_of(Jf, 0.01 * gaussian(n, 2, rng), r0, m), 3, 0, 25.0);
  CHECK_FALSE(small.visible);
  CHECK_FALSE(small.absorbed);

  // A chi-square change within tol of the threshold is left undecided.
  CandidateGrams edge;
  edge.raw = edge.perp = Eigen::MatrixXd::Constant(1, 1, 25.0 + 1e-9);
  edge.perp_r = Eigen::VectorXd::Constant(1, 1.0);
  edge.rr = 300.0;
  edge.n = 300.0;
  CHECK_FALSE(score_columns(Eigen::VectorXd::Ones(1), edge, 0, 0, 25.0, 1e-6).decided);
  CHECK(score_columns(Eigen::VectorXd::Ones(1), edge, 0, 0, 25.0).visible);
}

TEST_CASE("Blocked folds and the cross-validated RMS of a mean", "[scoring]") {
  std::vector<int> f;
  for (std::size_t i = 0; i < 10; ++i) f.push_back(contiguous_block(i, 10, 3));
  CHECK(f == std::vector<int>{0, 0, 0, 0, 1, 1, 1, 2, 2, 2});
  CHECK(contiguous_block(9, 10, 3, 1) == 0);
  CHECK(contiguous_block(0, 10, 3, 2) == 2);

  // y ~ a constant, two blocks: each block is predicted by the other's mean (mm -> um).
  const Eigen::VectorXd y =
      (Eigen::VectorXd(6) << 1.0, 2.0, 3.0, 10.0, 11.0, 15.0).finished() * 1e-3;
  const Eigen::MatrixXd X = Eigen::MatrixXd::Ones(6, 1);
  const std::vector<int> fold = {0, 0, 0, 1, 1, 1};
  const double mean0 = 2.0, mean1 = 12.0;
  double ss = 0.0;
  for (double v : {1.0, 2.0, 3.0}) ss += (v - mean1) * (v - mean1);
  for (double v : {10.0, 11.0, 15.0}) ss += (v - mean0) * (v - mean0);
  const double expected = std::sqrt(ss / 6.0);
  CHECK(cv_rms_um(X, y, fold, 2) == Approx(expected).epsilon(1e-12));
  // The fit is the caller's: one that always answers zero predicts zero.
  CHECK(blocked_cv_rms_um(X, y, fold, 2, [](const std::vector<Eigen::Index>&) {
          return Eigen::VectorXd::Zero(1).eval();
        }) == Approx(y.norm() / std::sqrt(6.0) * 1e3).epsilon(1e-12));
  // No columns: the prediction is zero.
  CHECK(cv_rms_um(Eigen::MatrixXd(6, 0), y, fold, 2) ==
        Approx(y.norm() / std::sqrt(6.0) * 1e3).epsilon(1e-12));
}
