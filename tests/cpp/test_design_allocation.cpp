// SPDX-License-Identifier: BSD-3-Clause
// design/allocation.hpp: the allocation of runs among candidates, on information matrices whose
// best allocation is known in closed form.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "rotacal/core/error.hpp"
#include "rotacal/design/allocation.hpp"

using namespace rotacal;

namespace {
Eigen::MatrixXd diag(double a, double b) {
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(2, 2);
  I(0, 0) = a, I(1, 1) = b;
  return I;
}

AllocationProblem two_parameters(std::vector<Eigen::MatrixXd> candidates, int runs) {
  AllocationProblem P;
  P.candidates = std::move(candidates);
  P.runs = runs;
  P.target = ParameterBlock{"x", 0, 2, 1, {"a", "b"}, {"mm", "mm"}};
  P.scale = Eigen::Vector2d(2.0, 2.0);
  P.plausible = Eigen::Vector2d(1.0, 1.0);
  return P;
}
}  // namespace

TEST_CASE("runs go where they equalise the variances", "[design][allocation]") {
  // One run of the first sees a with information 4, of the second b with 1: with 5 runs,
  // max(2 / sqrt(4 n1), 2 / sqrt(n2)) is smallest at n1 = 1, n2 = 4 (both 1); the third
  // candidate sees both a little and is not worth a run.
  const Allocation a = allocate_runs(two_parameters({diag(4, 0), diag(0, 1), diag(0.05, 0.05)}, 5));
  REQUIRE(a.counts.size() == 3);
  CHECK(a.counts[0] == 1);
  CHECK(a.counts[1] == 4);
  CHECK(a.counts[2] == 0);
  CHECK(a.uncertainty.feasible);
  CHECK(a.uncertainty.worst == Approx(1.0));
  CHECK(a.inverted.sigma[0] == Approx(0.5));
}

TEST_CASE("a parameter no candidate determines is left out of the criterion",
          "[design][allocation]") {
  const Allocation a = allocate_runs(two_parameters({diag(4, 0), diag(1, 0)}, 3));
  REQUIRE(a.determinable.size() == 2);
  CHECK(a.determinable[0]);
  CHECK_FALSE(a.determinable[1]);
  CHECK(a.counts[0] == 3);  // the most informative candidate takes every run
  CHECK(a.uncertainty.feasible);
  CHECK(a.uncertainty.worst == Approx(2.0 / std::sqrt(12.0)));
  CHECK(a.uncertainty.worst_index == 0);
}

TEST_CASE("correlated candidates: the allocation is the best of every allocation",
          "[design][allocation]") {
  // Candidates reading a + b, a - b, a + b four times as well, and 2a + b/2; every allocation of 4
  // and of 7 runs enumerated, its largest 2 sigma from the closed-form 2 x 2 inverse.
  Eigen::MatrixXd plus(2, 2), minus(2, 2), cross;
  plus << 1, 1, 1, 1;
  minus << 1, -1, -1, 1;
  cross = Eigen::Vector2d(2.0, 0.5) * Eigen::RowVector2d(2.0, 0.5);
  const std::vector<Eigen::MatrixXd> cands = {plus, minus, 4 * plus, cross};
  for (int runs : {4, 7}) {
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= runs; ++i)
      for (int j = 0; i + j <= runs; ++j)
        for (int k = 0; i + j + k <= runs; ++k) {
          const Eigen::MatrixXd M =
              i * cands[0] + j * cands[1] + k * cands[2] + (runs - i - j - k) * cands[3];
          const double det = M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0);
          if (!(det > 1e-9)) continue;
          best = std::min(best, 2.0 * std::sqrt(std::max(M(1, 1), M(0, 0)) / det));
        }
    const Allocation a = allocate_runs(two_parameters(cands, runs));
    INFO(runs << " runs: best " << best << ", allocated " << a.uncertainty.worst);
    CHECK(a.uncertainty.worst == Approx(best).epsilon(1e-9));
    CHECK(a.counts[0] + a.counts[1] + a.counts[2] + a.counts[3] == runs);
  }
}

TEST_CASE("invalid problems are refused", "[design][allocation]") {
  CHECK_THROWS_AS(allocate_runs(two_parameters({}, 3)), InvalidArgument);
  CHECK_THROWS_AS(allocate_runs(two_parameters({diag(1, 1)}, 0)), InvalidArgument);
  CHECK_THROWS_AS(allocate_runs(two_parameters({diag(1, 1), Eigen::MatrixXd::Identity(3, 3)}, 2)),
                  InvalidArgument);
}
