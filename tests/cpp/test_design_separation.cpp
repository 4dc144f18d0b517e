// SPDX-License-Identifier: BSD-3-Clause
// design/separation.hpp: the information algebra (inverse with held parameters, canonical
// correlation, columns between layouts) and the one separation search, on information
// matrices whose correlations are known in closed form.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "rotacal/design/separation.hpp"

using namespace rotacal;

namespace {
// Two parameters "a" and "b" (one block each), in mm.
ParameterLayout pair_layout() {
  ParameterLayout L;
  L.add("a", {"a"}, {"mm"});
  L.add("b", {"b"}, {"mm"});
  return L;
}

// Information k [[1, c], [c, 1]]: the estimates' correlation is -c (covariance ~ [[1, -c], [-c,
// 1]]).
Eigen::MatrixXd correlated(double k, double c) {
  Eigen::MatrixXd I(2, 2);
  I << 1.0, c, c, 1.0;
  return k * I;
}
}  // namespace

TEST_CASE(
    "inverse of an information matrix: 1 / sqrt(information) when diagonal; a parameter nothing "
    "sees is held") {
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(3, 3);
  I(0, 0) = 400.0, I(1, 1) = 25.0;  // the third: no information
  const Inverted inv = invert_information(I, Eigen::VectorXd::Ones(3), 1.0);
  CHECK(inv.sigma[0] == Approx(0.05));
  CHECK(inv.sigma[1] == Approx(0.2));
  CHECK_FALSE(inv.determined[2]);
  CHECK(inv.sigma[2] == std::numeric_limits<double>::infinity());
}

TEST_CASE("canonical correlation of two one-parameter blocks is their correlation") {
  const ParameterLayout L = pair_layout();
  for (double c : {0.0, 0.3, 0.9}) {
    const Inverted inv = invert_information(correlated(100.0, c), Eigen::VectorXd::Ones(2), 1.0);
    CHECK(canonical_correlation(inv, L.block("a"), L.block("b")) == Approx(c).margin(1e-12));
  }
}

TEST_CASE("columns move between layouts by block") {
  ParameterLayout from, to;
  const ParameterBlock fa = from.add("a", 2, "mm"), fb = from.add("b", 1, "mm");
  const ParameterBlock tb = to.add("b", 1, "mm"), tx = to.add("x", 3, "mm"),
                       ta = to.add("a", 2, "mm");
  Eigen::MatrixXd J(2, 3);
  J << 1, 2, 3, 4, 5, 6;
  const Eigen::MatrixXd out = in_layout(J, {fa, fb}, {ta, tb}, to.size());
  Eigen::MatrixXd expected(2, 6);
  expected << 3, 0, 0, 0, 1, 2, 6, 0, 0, 0, 4, 5;
  CHECK(out == expected);
  CHECK(tx.columns(out).isZero());
}

TEST_CASE(
    "the search takes the shortest run below the target, and the lowest correlation when none "
    "reaches it") {
  // Session: correlation 0.9. A candidate adding d (k = 100) on both diagonals run r times
  // leaves 90 / (100 + r d): below 0.5 when r d > 80.
  const ParameterLayout L = pair_layout();
  SeparationProblem S;
  S.session_information = correlated(100.0, 0.9);
  S.plausible = Eigen::VectorXd::Ones(2);
  S.first = L.block("a");
  S.second = L.block("b");
  S.max_correlation = 0.5;
  S.max_added_time_s = 100.0;
  SeparationResult D;
  D.effects = {"a", "b"};
  REQUIRE(separation_needed(S, D));
  CHECK(D.correlation_before == Approx(0.9));
  const Eigen::MatrixXd slow = 30.0 * Eigen::MatrixXd::Identity(2, 2);   // needs r = 4 (run 40 s)
  const Eigen::MatrixXd fast = 100.0 * Eigen::MatrixXd::Identity(2, 2);  // r = 1 (run 30 s)
  const std::vector<AddedInformation> added = {{10.0, slow, true}, {30.0, fast, true}};
  SeparationChoice c = search_separation(S, added);
  REQUIRE(c.found);
  CHECK(c.index == 1);
  CHECK(c.repeats == 1.0);
  CHECK(c.correlation == Approx(90.0 / 200.0));
  CHECK(c.determined);
  // Within 35 s only the second reaches the target; when it may not be repeated and needs 2
  // runs, none does and the lowest correlation is kept.
  S.max_added_time_s = 35.0;
  CHECK(search_separation(S, added).index == 1);
  const std::vector<AddedInformation> weak = {{10.0, slow, true}, {30.0, 0.5 * fast, false}};
  c = search_separation(S, weak);
  CHECK_FALSE(c.found);
  CHECK(c.index == 0);  // 10 s run twice (20 s): 90 / 160 = 0.5625 < 90 / 150
  CHECK(c.repeats == 2.0);
  CHECK(c.correlation == Approx(90.0 / 160.0));
  D.candidates_tried = 2;
  finish_separation(S, c, "the first", 20.0, {}, SeparationWording{}, D);
  CHECK_FALSE(D.found);
  CHECK_THAT(D.verdict, Catch::StartsWith("none of 2 added tests within 35 s") &&
                            Catch::Contains("the closest is the first (correlation 0.56)"));
}

TEST_CASE("no search when the session separates the pair already") {
  const ParameterLayout L = pair_layout();
  SeparationProblem S;
  S.session_information = correlated(100.0, 0.2);
  S.plausible = Eigen::VectorXd::Ones(2);
  S.first = L.block("a");
  S.second = L.block("b");
  SeparationResult D;
  D.effects = {"a", "b"};
  CHECK_FALSE(separation_needed(S, D));
  CHECK(D.already_separated);
  CHECK_THAT(D.verdict,
             Catch::StartsWith("the session alone separates a and b (correlation 0.20 < 0.50)"));
}
