// SPDX-License-Identifier: BSD-3-Clause
// core/parameter_layout.hpp: named blocks, their offsets, views over Eigen vectors, Jacobian
// columns and raw double / Jet arrays, items of zeros per nest, and the errors it throws.
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/core/parameter_layout.hpp"

using namespace rotacal;

namespace {
// A ballbar-like layout with two pivots and three effect parameters, and zeros of two nests.
ParameterLayout example() {
  ParameterLayout L;
  L.add("location_errors", {"X_OC", "Y_OC", "A_OC", "B_OC", "Y_OA", "Z_OA", "B_OA", "C_OA"},
        {"mm", "mm", "rad", "rad", "mm", "mm", "rad", "rad"});
  L.add("pivot", {"pivot_x", "pivot_y", "pivot_z"}, {"mm"});
  L.add("zeros", {"zero.1.x", "zero.1.y", "zero.1.z", "zero.2.x", "zero.2.y", "zero.2.z"}, {"mm"},
        3);
  L.add("effects", 3, "1");
  L.add("radius", 0, "mm");
  return L;
}
}  // namespace

TEST_CASE("blocks follow one another in the order they were added") {
  const ParameterLayout L = example();
  CHECK(L.size() == 8 + 3 + 6 + 3);
  CHECK(L.block("location_errors").offset == 0);
  CHECK(L.block("pivot").offset == 8);
  CHECK(L.block("pivot").size == 3);
  CHECK(L.block("zeros").offset == 11);
  CHECK(L.block("zeros").items() == 2);
  CHECK(L.block("effects").offset == 17);
  CHECK(L.block("effects").end() == 20);
  CHECK(L.block("radius").empty());
  CHECK(L.block("radius").offset == 20);
  CHECK(L.has("pivot"));
  CHECK_FALSE(L.has("sphere"));
  CHECK(L.block_of(9).name == "pivot");
  CHECK(L.block_of(19).name == "effects");
}

TEST_CASE("names and units in vector order, a single unit given to the whole block") {
  const ParameterLayout L = example();
  const std::vector<std::string> n = L.names(), u = L.units();
  REQUIRE(n.size() == 20);
  REQUIRE(u.size() == 20);
  CHECK(n[0] == "X_OC");
  CHECK(n[8] == "pivot_x");
  CHECK(n[14] == "zero.2.x");
  CHECK(n[17] == "effects[0]");
  CHECK(u[2] == "rad");
  CHECK(u[10] == "mm");
  CHECK(u[19] == "1");
}

TEST_CASE("a block's segment reads and writes the vector at its offset") {
  const ParameterLayout L = example();
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(20, 0.0, 19.0);
  const ParameterBlock pivot = L.block("pivot");
  CHECK(pivot.of(x) == Eigen::Vector3d(8.0, 9.0, 10.0));
  CHECK(pivot.of<3>(x) == Eigen::Vector3d(8.0, 9.0, 10.0));
  pivot.of(x) = Eigen::Vector3d(-1.0, -2.0, -3.0);
  CHECK(x[9] == -2.0);
  CHECK(x[11] == 11.0);
  const Eigen::VectorXd& cx = x;
  CHECK(L.block("effects").of(cx).sum() == 17.0 + 18.0 + 19.0);
  CHECK_THROWS_AS(pivot.of<2>(x), InvalidArgument);
}

TEST_CASE("an item of the zeros block is the nest's three components") {
  const ParameterLayout L = example();
  const ParameterBlock zeros = L.block("zeros");
  const ParameterBlock second = zeros.item(1);
  CHECK(second.offset == 14);
  CHECK(second.size == 3);
  CHECK(second.names == std::vector<std::string>{"zero.2.x", "zero.2.y", "zero.2.z"});
  CHECK(second.name == "zeros[1]");
  CHECK(zeros.item_offset(1) == 14);
  CHECK_THROWS_AS(zeros.item(2), InvalidArgument);
  CHECK_THROWS_AS(zeros.item(-1), InvalidArgument);
}

TEST_CASE("a part of a block is a block at the part's offset, with its names") {
  const ParameterLayout L = example();
  const ParameterBlock second = L.block("effects").part(1, 2, "second");
  CHECK(second.offset == 18);
  CHECK(second.size == 2);
  CHECK(second.name == "second");
  CHECK(second.names == std::vector<std::string>{"effects[1]", "effects[2]"});
  CHECK(L.block("effects").part(3, 0, "none").empty());
  CHECK_THROWS_WITH(L.block("effects").part(2, 2, "x"),
                    Catch::Contains("effects: parameters 2..4 of 3"));
  CHECK_THROWS_AS(L.block("effects").part(-1, 1, "x"), InvalidArgument);
}

TEST_CASE("raw pointers serve doubles and Jets alike, and an empty block gives nullptr") {
  const ParameterLayout L = example();
  std::vector<double> p(20);
  for (std::size_t k = 0; k < p.size(); ++k) p[k] = static_cast<double>(k);
  const double* const cp = p.data();
  CHECK(*L.block("effects").ptr(cp) == 17.0);
  CHECK(L.block("radius").ptr(cp) == nullptr);
  using Jet = ceres::Jet<double, 4>;
  std::vector<Jet> pj(20);
  for (std::size_t k = 0; k < pj.size(); ++k)
    pj[k] = Jet(static_cast<double>(k), static_cast<int>(k % 4));
  const Jet* const cj = pj.data();
  const Jet* z = L.block("zeros").item(1).ptr(cj);
  CHECK(z[2].a == 16.0);
  CHECK(z[2].v[0] == 1.0);  // index 16 carries direction 16 % 4 = 0
  Jet* w = L.block("pivot").ptr(pj.data());
  w[0] = Jet(5.0);
  CHECK(pj[8].a == 5.0);
}

TEST_CASE("a block's Jacobian columns") {
  const ParameterLayout L = example();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(4, L.size());
  L.block("pivot").columns(J).setOnes();
  CHECK(J.sum() == 12.0);
  CHECK(J.col(8).sum() == 4.0);
  CHECK(J.col(11).sum() == 0.0);
  const Eigen::MatrixXd& cJ = J;
  CHECK(L.block("pivot").columns(cJ).cols() == 3);
}

TEST_CASE("bad layouts and unknown names are refused, naming the block") {
  ParameterLayout L = example();
  CHECK_THROWS_WITH(L.add("pivot", 3, "mm"), Catch::Contains("pivot added twice"));
  CHECK_THROWS_WITH(L.add("sphere", {"a", "b"}, {"mm", "mm", "mm"}),
                    Catch::Contains("sphere has 2 names but 3 units"));
  CHECK_THROWS_WITH(L.add("nests", {"a", "b", "c", "d"}, {"mm"}, 3), Catch::Contains("nests of 4"));
  CHECK_THROWS_WITH(L.block("sphere"), Catch::Contains("no block named sphere"));
  CHECK_THROWS_WITH(L.block_of(20), Catch::Contains("index 20 outside the 20"));
  CHECK(L.size() == 20);  // the refused blocks left no trace
}
