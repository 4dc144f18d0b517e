// SPDX-License-Identifier: BSD-3-Clause
// ballbar/problem.hpp: the ballbar layout, its one residual (doubles and Jets) and the fit
// set-up built from the layout.
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <vector>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/ballbar/problem.hpp"

using namespace rotacal;

namespace {
BallbarArrays commanded(const std::string& machine) {
  BallbarSetup setup;
  setup.machine = parse_machine_type(machine);
  setup.tilt_range_deg = default_tilt_range_deg(setup.machine);
  setup.step_deg = 15.0;
  return ballbar_arrays(commanded_session(plan_ballbar_test(setup)));
}
}  // namespace

TEST_CASE("the ballbar layout: location errors, pivots, effects, with the fit's names") {
  EffectModel fx;
  fx.effects = {Effect::parse("ballbar_length_offset"), Effect::parse("tilt_motion_C_h1")};
  const BallbarLayout one = ballbar_layout(MachineType::AC_trt, fx);
  CHECK(one.errors.offset == 0);
  CHECK(one.errors.names ==
        std::vector<std::string>(location_error_names(MachineType::AC_trt).begin(),
                                 location_error_names(MachineType::AC_trt).end()));
  CHECK(one.pivots.offset == 8);
  CHECK(one.pivots.names == std::vector<std::string>{"pivot_x", "pivot_y", "pivot_z"});
  CHECK(one.effects.offset == 11);
  CHECK(one.effects.size == 1 + 4);
  CHECK(one.effects.names.front() == "ballbar_length_offset");     // one parameter: the id
  CHECK(one.effects.names[1].rfind("tilt_motion_C_h1.", 0) == 0);  // several: id.parameter
  const BallbarLayout two = ballbar_layout(MachineType::AC_trt, fx, 2);
  CHECK(two.pivots.size == 6);
  CHECK(two.pivots.item(1).names ==
        std::vector<std::string>{"pivot_x#2", "pivot_y#2", "pivot_z#2"});
  CHECK(two.effects.offset == 14);
  CHECK_THROWS_AS(ballbar_layout(MachineType::AC_trt, fx, 0), InvalidArgument);
}

TEST_CASE(
    "the residual is zero on the commanded session at the nominal pivot, and the pivot block moves "
    "it") {
  const BallbarArrays a = commanded("AC-trt");
  const EffectModel fx;
  const BallbarLayout L = ballbar_layout(a.machine, fx);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(L.all.size());
  L.pivots.of<3>(x) = a.pivot;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    CHECK(std::abs(ballbar_residual<double>(L, a, fx, x.data(), i)) < 1e-10);
  // d r / d pivot by Jets against central differences of the doubles.
  using Jet = ceres::Jet<double, 3>;
  std::vector<Jet> xj(static_cast<std::size_t>(L.all.size()));
  for (Eigen::Index j = 0; j < L.all.size(); ++j) xj[static_cast<std::size_t>(j)] = Jet(x[j]);
  for (int k = 0; k < 3; ++k) xj[static_cast<std::size_t>(L.pivots.offset + k)].v[k] = 1.0;
  for (Eigen::Index i = 0; i < a.size(); i += 7) {
    const Jet r = ballbar_residual<Jet>(L, a, fx, xj.data(), i);
    for (int k = 0; k < 3; ++k) {
      Eigen::VectorXd xp = x, xm = x;
      xp[L.pivots.offset + k] += 1e-4, xm[L.pivots.offset + k] -= 1e-4;
      const double fd = (ballbar_residual<double>(L, a, fx, xp.data(), i) -
                         ballbar_residual<double>(L, a, fx, xm.data(), i)) /
                        2e-4;
      CHECK(r.v[k] == Approx(fd).margin(1e-8));
    }
  }
  // Moving the centre pivot along the bar direction of a sample lengthens or shortens it.
  Eigen::VectorXd moved = x;
  L.pivots.of<3>(moved) += Eigen::Vector3d(0.0, 0.0, 0.05);
  double largest = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    largest = std::max(largest, std::abs(ballbar_residual<double>(L, a, fx, moved.data(), i)));
  CHECK(largest > 0.01);
  CHECK(largest <= 0.05 + 1e-12);
}

TEST_CASE(
    "the fit set-up: start at the nominal pivot; on a head the tool length is baseline and does "
    "not yield") {
  const BallbarArrays a = commanded("AC-trt");
  JointFitOptions o;
  o.effects.effects = {Effect::parse("tilt_motion_C_h1")};
  const BallbarFitSetup s = ballbar_fit_setup(a, o);
  REQUIRE(static_cast<Eigen::Index>(s.parameters.size()) == s.layout.all.size());
  for (int k = 0; k < 3; ++k)
    CHECK(s.parameters[static_cast<std::size_t>(8 + k)].start == a.pivot[k]);
  CHECK(s.parameters[2].unit == "rad");
  for (Eigen::Index j = s.layout.effects.offset; j < s.layout.effects.end(); ++j)
    CHECK(s.parameters[static_cast<std::size_t>(j)].yields);
  const BallbarArrays h = commanded("AC-head");
  const BallbarFitSetup sh = ballbar_fit_setup(h, o);
  REQUIRE(sh.effects.effects.front() == Effect::parse("tool_offset_Z"));
  CHECK(sh.parameters[static_cast<std::size_t>(sh.layout.effects.offset)].name == "tool_offset_Z");
  CHECK_FALSE(sh.parameters[static_cast<std::size_t>(sh.layout.effects.offset)].yields);
  CHECK(sh.parameters.back().yields);
  // The model at a solution reads each block where the layout puts it.
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(sh.layout.all.size(), 1.0,
                                                 static_cast<double>(sh.layout.all.size()));
  const BallbarMachineModel m = ballbar_model_at(sh, h.machine, x);
  CHECK(m.errors.v[7] == 8.0);
  CHECK(m.pivot == Eigen::Vector3d(9.0, 10.0, 11.0));
  CHECK(m.effect_params.front() == 12.0);
  CHECK(m.effect_params.size() == static_cast<std::size_t>(sh.layout.effects.size));
}
