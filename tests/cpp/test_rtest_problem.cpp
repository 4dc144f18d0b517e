// SPDX-License-Identifier: BSD-3-Clause
// rtest/problem.hpp: the R-test layout (with and without maps, on table and head machines),
// the arrays, and the residual model's two table poses with their Jacobians against central
// differences.
#include <catch2/catch.hpp>
#include <vector>

#include "rotacal/rtest/problem.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
// Noise-free readings of a small pattern on `truth` (two nests), with its probe zeros.
RtestSession small_session(const MachineModel& truth) {
  RtestSimOptions o;
  o.pattern.b_deg = {-60.0, -30.0, 0.0, 30.0, 60.0};
  o.pattern.c_deg = {0.0, 60.0, 120.0, 180.0, 240.0, 300.0};
  o.noise_um = 0.0;
  return simulate_rtest(truth, o).session;
}

// J of `model` at x against central differences of its residuals.
double jacobian_error(const ResidualModel& model, const Eigen::VectorXd& x) {
  Eigen::VectorXd r(model.num_residuals()), rp(model.num_residuals()), rm(model.num_residuals());
  Eigen::MatrixXd J(model.num_residuals(), model.num_parameters());
  model.evaluate(x, r, &J);
  double worst = 0.0;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += 1e-6, xm[j] -= 1e-6;
    model.evaluate(xp, rp, nullptr);
    model.evaluate(xm, rm, nullptr);
    worst = std::max(worst, ((rp - rm) / 2e-6 - J.col(j)).cwiseAbs().maxCoeff());
  }
  return worst;
}
}  // namespace

TEST_CASE(
    "the R-test layout: tool length only on a head, maps only with a basis, zeros per set-up") {
  EffectModel fx;
  fx.effects = {Effect::parse("gravity_sag_B")};
  const RtestLayout t = rtest_layout(MachineType::BC_trt, {"1", "2"}, nullptr, fx);
  CHECK(t.errors.size == 8);
  CHECK(t.tool.empty());
  CHECK(t.map_tilt.empty());
  CHECK(t.map_rot.empty());
  CHECK(t.zeros.offset == 8);
  CHECK(t.zeros.items() == 2);
  CHECK(t.zeros.item(1).names == std::vector<std::string>{"zero.2.x", "zero.2.y", "zero.2.z"});
  CHECK(t.effects.offset == 14);
  CHECK(t.effects.names == std::vector<std::string>{"gravity_sag_B"});
  const RtestLayout n =
      rtest_layout(MachineType::BC_trt, {"1"}, nullptr, fx, RtestZeroNames::numbered);
  CHECK(n.zeros.names.front() == "zero_x#1");
  const RtestBasis basis;
  const RtestLayout h = rtest_layout(parse_machine_type("BC-head"), {"1"}, &basis, EffectModel{});
  CHECK(h.tool.offset == 8);
  CHECK(h.tool.names == std::vector<std::string>{"tool_offset_Z"});
  const RtestBasis hb = basis.for_machine(parse_machine_type("BC-head"));
  CHECK(h.map_tilt.size == hb.num_b_coefficients());
  CHECK(h.map_rot.size == hb.num_c_coefficients());
  CHECK(h.map_tilt.offset == 9);
  CHECK(h.zeros.offset == 9 + hb.num_b_coefficients() + hb.num_c_coefficients());
  // Translations in mm, rotations in rad, as the coefficient's component says.
  for (std::size_t k = 0; k < h.map_tilt.names.size(); ++k)
    CHECK(h.map_tilt.units[k] == (h.map_tilt.names[k][0] == 'd' ? "mm" : "rad"));
}

TEST_CASE(
    "the machine model's residuals: zero at the truth, Jacobian equal to central differences") {
  MachineModel truth = MachineModel::nominal(MachineType::BC_trt);
  truth.errors.v << 0.01, -0.02, 1e-4, -2e-4, 0.015, 0.005, 5e-5, -1e-4;
  const RtestSession s = small_session(truth);
  const RtestArrays a = rtest_arrays(s, "test");
  const RtestProblem model(a, nullptr, EffectModel{});
  const RtestLayout& L = model.layout();
  REQUIRE(model.num_residuals() == 3 * static_cast<Eigen::Index>(s.samples.size()));
  // The truth's location errors in their block; the probe zeros (random in the simulation)
  // are what is left, one constant per set-up.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(L.all.size());
  L.errors.of<8>(x) = truth.errors.v;
  Eigen::VectorXd r(model.num_residuals());
  model.evaluate(x, r, nullptr);
  // Without the zeros the residuals are minus each set-up's constant zero.
  for (std::size_t k = 0; k < a.setups.size(); ++k) {
    Eigen::Vector3d first = Eigen::Vector3d::Constant(NAN);
    for (Eigen::Index i = 0; i < a.size(); ++i)
      if (a.setup_of[static_cast<std::size_t>(i)] == static_cast<int>(k)) {
        if (std::isnan(first[0])) first = r.segment<3>(3 * i);
        CHECK((r.segment<3>(3 * i) - first).cwiseAbs().maxCoeff() < 1e-9);
      }
    L.zeros.item(static_cast<Eigen::Index>(k)).of<3>(x) = -first;
  }
  model.evaluate(x, r, nullptr);
  CHECK(r.cwiseAbs().maxCoeff() < 1e-9);
  CHECK(jacobian_error(model, x) < 1e-6);
}

TEST_CASE("the joint model's residuals: Jacobian through the basis equal to central differences") {
  const RtestSession s = small_session(MachineModel::nominal(MachineType::BC_trt));
  const RtestArrays a = rtest_arrays(s, "test");
  RtestBasis basis;
  basis.b_degree = 3;
  basis.c_harmonics = 1;
  const RtestBasis b = basis.for_machine(MachineType::BC_trt);
  const RtestProblem model(a, &b, EffectModel{});
  const RtestLayout& L = model.layout();
  CHECK(L.map_tilt.size == b.num_b_coefficients());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(L.all.size());
  for (Eigen::Index j = 0; j < x.size(); ++j)
    x[j] = 1e-4 * std::sin(1.0 + 3.0 * static_cast<double>(j));
  CHECK(jacobian_error(model, x) < 1e-6);
}

TEST_CASE("maps and effects together are refused, and a sample without d is named") {
  const RtestSession s = small_session(MachineModel::nominal(MachineType::BC_trt));
  const RtestArrays a = rtest_arrays(s, "test");
  EffectModel fx;
  fx.effects = {Effect::parse("gravity_sag_B")};
  const RtestBasis b = RtestBasis{}.for_machine(MachineType::BC_trt);
  CHECK_THROWS_WITH(RtestProblem(a, &b, fx), Catch::Contains("give one"));
  RtestSession no_d = s;
  no_d.samples[3].d.reset();
  CHECK_THROWS_WITH(rtest_arrays(no_d, "who"),
                    Catch::Contains("who: sample 3") && Catch::Contains("dx,dy,dz"));
  CHECK_NOTHROW(rtest_arrays(no_d, "who", false));
  RtestSession no_nest = s;
  no_nest.nests.erase(no_nest.nests.begin());
  CHECK_THROWS_WITH(rtest_arrays(no_nest, "who"), Catch::Contains("no nest."));
}
