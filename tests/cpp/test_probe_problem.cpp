// SPDX-License-Identifier: BSD-3-Clause
// The probe problem (probe/problem.hpp): its named blocks tile the parameter vector in the
// stated order, its parameters carry the names and units of the blocks, and its Jacobian (Jets
// of the one touch model) agrees with central differences.
#include <catch2/catch.hpp>

#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/simulate.hpp"

using namespace rotacal;

namespace {
MachineModel plausible_machine(MachineType m) {
  MachineModel t = MachineModel::nominal(m);
  t.errors.v << 0.03, -0.02, 2e-5, -3e-5, 0.01, 0.04, -1e-5, 2e-5;
  return t;
}
}  // namespace

TEST_CASE("the blocks tile the parameter vector, named", "[probe]") {
  const EffectModel fx{{Effect::parse("probe_lobing")}, std::nullopt};
  for (const char* name : {"AC-trt", "B-head-C-table"}) {
    const MachineType m = parse_machine_type(name);
    const ProbeParameterLayout L = ProbeParameterLayout::make(m, fx);
    const int tool = m.has_head() ? 1 : 0;
    CHECK(L.errors.offset == 0);
    CHECK(L.tool_length.offset == 8);
    CHECK(L.tool_length.size == tool);
    CHECK(L.sphere.offset == 8 + tool);
    CHECK(L.effects.offset == 11 + tool);
    CHECK(L.size() == 13 + tool);
    ProbeSimOptions o;
    o.pattern = default_probe_pattern(m);
    const ProbeProblem problem(simulate_probe(MachineModel::nominal(m), o).session, fx);
    const std::vector<FitParameter> p = problem.parameters();
    REQUIRE(static_cast<int>(p.size()) == L.size());
    CHECK(p[static_cast<std::size_t>(L.sphere.offset)].name == "sphere.x");
    CHECK(p[static_cast<std::size_t>(L.sphere.offset)].start == 150.0);
    CHECK(p[static_cast<std::size_t>(L.effects.offset) + 1].name == "probe_lobing.ls");
    CHECK(p[static_cast<std::size_t>(L.effects.offset)].yields);
    if (tool) CHECK(p[8].name == "tool_offset_Z");
  }
  ProbeSession none;
  CHECK_THROWS_AS(ProbeProblem(none), InvalidArgument);
}

TEST_CASE("the probe problem's Jacobian agrees with central differences", "[probe][identify]") {
  MachineModel t = plausible_machine(MachineType::BC_trt);
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(t.machine);
  const ProbeSession s = simulate_probe(t, o).session;
  const EffectModel fx{{Effect::parse("stylus_radius_offset"), Effect::parse("probe_lobing"),
                        Effect::parse("tilt_motion_C_h2")},
                       std::nullopt};
  const ProbeProblem problem(s, fx);
  const ProbeParameterLayout& L = problem.layout();
  CHECK(L.size() == 8 + 3 + 1 + 2 + 4);
  CHECK(L.sphere.offset == 8);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(L.size());
  x.segment(L.errors.offset, 8) = t.errors.v;
  x.segment<3>(L.sphere.offset) = s.sphere + Eigen::Vector3d(0.01, 0.02, -0.01);
  x.segment(L.effects.offset, L.effects.size) << 1e-3, 0.5e-3, -0.3e-3, 2e-6, -1e-6, 3e-6, 1e-6;
  Eigen::VectorXd r(problem.num_residuals());
  Eigen::MatrixXd J(problem.num_residuals(), problem.num_parameters());
  problem.evaluate(x, r, &J);
  for (int k = 0; k < problem.num_parameters(); ++k) {
    const double h = k >= L.sphere.offset && k < L.sphere.offset + 3 ? 1e-6 : 1e-7;
    Eigen::VectorXd xp = x, xm = x;
    xp[k] += h, xm[k] -= h;
    const Eigen::VectorXd fd = (problem.residuals(xp) - problem.residuals(xm)) / (2 * h);
    INFO("parameter " << problem.parameters()[static_cast<std::size_t>(k)].name);
    CHECK((J.col(k) - fd).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + fd.cwiseAbs().maxCoeff()));
  }
}
