// SPDX-License-Identifier: BSD-3-Clause
#include <Eigen/Cholesky>
#include <catch2/catch.hpp>
#include <limits>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/fit/box_least_squares.hpp"

using namespace rotacal;

namespace {
// 8 values, 3 correlated columns, weights of a noise model: the shape of the Table 2 analysis.
struct Problem {
  Eigen::MatrixXd R = Eigen::MatrixXd(8, 3);
  Eigen::VectorXd d = Eigen::VectorXd(8), w = Eigen::VectorXd(8);
};
Problem make_problem(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  Problem p;
  for (int i = 0; i < 8; ++i) {
    const double a = N(rng), b = N(rng);
    p.R.row(i) << a, 0.8 * a + 0.6 * b, N(rng);  // columns 0 and 1 correlated (cos 0.8)
    p.d[i] = N(rng);
    p.w[i] = 1.0 / (0.5 + 0.1 * i);
  }
  return p;
}
}  // namespace

TEST_CASE("box least squares with loose bounds is the weighted normal-equation solution", "[fit]") {
  const Problem p = make_problem(3);
  const Eigen::MatrixXd A = p.R.transpose() * p.w.asDiagonal() * p.R;
  const Eigen::VectorXd expected = A.ldlt().solve(p.R.transpose() * p.w.asDiagonal() * p.d);
  const Eigen::VectorXd s = box_least_squares(p.R, p.d, p.w, Eigen::VectorXd::Constant(3, 1e3));
  // It stops when a sweep moves no unknown by 1e-9 of its bound (1e-6 here); the distance left
  // to the minimum is that over (1 - the contraction per sweep), a few 1e-6 at cos 0.8.
  CHECK((s - expected).cwiseAbs().maxCoeff() < 1e-5);
}

TEST_CASE("box least squares meets the KKT conditions where a bound is active", "[fit]") {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Problem p = make_problem(seed);
    const Eigen::MatrixXd A = p.R.transpose() * p.w.asDiagonal() * p.R;
    const Eigen::VectorXd free_solution = A.ldlt().solve(p.R.transpose() * p.w.asDiagonal() * p.d);
    // Bounds at half the unconstrained solution's size: at least one is active.
    const Eigen::VectorXd bounds =
        0.5 * free_solution.cwiseAbs() + Eigen::VectorXd::Constant(3, 1e-3);
    const Eigen::VectorXd s = box_least_squares(p.R, p.d, p.w, bounds);
    // Gradient of 1/2 sum w (d - R s)^2: g = -R^T W (d - R s). At the minimum, g_j = 0 where
    // s_j is inside its bound, and g_j pushes outward (g_j s_j <= 0) where s_j is at its bound.
    const Eigen::VectorXd g = -p.R.transpose() * p.w.asDiagonal() * (p.d - p.R * s);
    const double scale = (p.R.transpose() * p.w.asDiagonal() * p.d).cwiseAbs().maxCoeff();
    bool active = false;
    for (int j = 0; j < 3; ++j) {
      REQUIRE(std::abs(s[j]) <= bounds[j] * (1.0 + 1e-12));
      if (std::abs(s[j]) >= bounds[j] * (1.0 - 1e-9)) {
        active = true;
        CHECK(g[j] * s[j] <= 1e-6 * scale * bounds[j]);
      } else {
        CHECK(std::abs(g[j]) < 1e-5 * scale);
      }
    }
    CHECK(active);
  }
}

TEST_CASE("box least squares: an unweighted column stays at zero, bad input throws", "[fit]") {
  Problem p = make_problem(5);
  p.R.col(2).setZero();
  const Eigen::VectorXd s = box_least_squares(p.R, p.d, p.w, Eigen::VectorXd::Constant(3, 10.0));
  CHECK(s[2] == 0.0);
  CHECK_THROWS_AS(box_least_squares(p.R, p.d.head(7), p.w, Eigen::VectorXd::Ones(3)),
                  InvalidArgument);
  CHECK_THROWS_AS(box_least_squares(p.R, p.d, p.w, Eigen::VectorXd::Ones(2)), InvalidArgument);
  CHECK_THROWS_AS(box_least_squares(p.R, p.d, -p.w, Eigen::VectorXd::Ones(3)), InvalidArgument);
  CHECK_THROWS_AS(box_least_squares(p.R, p.d, p.w, -Eigen::VectorXd::Ones(3)), InvalidArgument);
  Eigen::VectorXd bad = p.d;
  bad[0] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(box_least_squares(p.R, bad, p.w, Eigen::VectorXd::Ones(3)), InvalidArgument);
}
