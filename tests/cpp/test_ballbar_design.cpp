// Tests of the ballbar test design (rotacal/ballbar/design.hpp): the predicted 1-sigma is the
// one a simulated test realises, limits exclude set-ups by name, and the design beats the
// default set-up at the same run time.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "rotacal/ballbar/design.hpp"
#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/error.hpp"

using namespace rotacal;

TEST_CASE("the predicted sigma is what simulated tests of the set-up realise") {
  BallbarDesignOptions o;
  o.base.step_deg = 2.0;
  o.noise_um = 0.5;
  const BallbarPlan plan = plan_ballbar_test(o.base);
  const BallbarSession cmd = commanded_session(plan);
  // A recorder rate that records exactly the plan's samples in the plan's own run time.
  double t_tests = 0.0;
  for (const PlanSegment& seg : plan.segments)
    if (seg.kind == SegmentKind::test) t_tests += seg.samples.back().time - seg.samples.front().time;
  o.sample_rate_hz = static_cast<double>(cmd.samples.size()) / t_tests;
  const DesignCandidate c = evaluate_design(o.base, o, 0.0);
  REQUIRE(c.feasible);
  REQUIRE(c.sigma.size() == 11);

  BallbarMachineModel truth;
  truth.machine = cmd.machine;
  truth.pivot = cmd.pivot;
  truth.errors.v << 0.03, -0.02, 4e-5, -3e-5, 0.02, 0.01, 2e-5, -5e-5;
  const int draws = 60;
  Eigen::MatrixXd est(draws, 8);
  for (int k = 0; k < draws; ++k) {
    const BallbarSession s = simulate_ballbar(cmd, truth, {o.noise_um, static_cast<std::uint64_t>(100 + k), true});
    const BallbarIdentification id = identify_joint(s);
    for (int i = 0; i < 8; ++i) est(k, i) = id.parameters[static_cast<std::size_t>(i)].value;
  }
  for (int i = 0; i < 8; ++i) {
    const Eigen::VectorXd v = est.col(i);
    const double sd = std::sqrt((v.array() - v.mean()).square().sum() / (draws - 1));
    INFO(c.names[static_cast<std::size_t>(i)] << ": realised " << sd << ", predicted " << c.sigma[i]);
    CHECK(sd / c.sigma[i] > 0.7);
    CHECK(sd / c.sigma[i] < 1.4);
  }
}

TEST_CASE("travel limits exclude set-ups by name; the design beats the default at the same run time") {
  BallbarDesignOptions o;
  o.base.step_deg = 3.0;
  o.pivot_x_mm = {60.0, 120.0, 180.0};
  o.pivot_z_mm = {30.0, 60.0, 120.0};
  o.bar_lengths_mm = {100.0, 150.0};
  o.travel_max.z() = 250.0;  // a pivot 120 mm up and a 150 mm bar cannot be reached
  const BallbarDesign d = design_ballbar_test(o);
  REQUIRE(d.baseline.feasible);
  REQUIRE(d.best.feasible);
  bool refused_by_z = false;
  for (const DesignCandidate& c : d.candidates)
    if (!c.feasible && c.why_not.find("Z = ") != std::string::npos) refused_by_z = true;
  CHECK(refused_by_z);
  CHECK(d.time_budget_s == Approx(d.baseline.duration_s));
  CHECK(d.best.worst_expanded_um <= d.baseline.worst_expanded_um);
  CHECK(d.ratio == Approx(d.best.worst_expanded_um / d.baseline.worst_expanded_um));
  // More time, less uncertainty, as 1/sqrt(time) for the same geometry.
  const DesignCandidate twice = evaluate_design(d.best.setup, o, 4.0 * d.time_budget_s);
  CHECK(twice.worst_expanded_um == Approx(0.5 * d.best.worst_expanded_um).epsilon(1e-6));
  // AR(1) noise costs information: (1 + rho) / (1 - rho) more variance.
  BallbarDesignOptions ar = o;
  ar.noise_rho = 0.5;
  const DesignCandidate c_ar = evaluate_design(d.best.setup, ar, d.time_budget_s);
  CHECK(c_ar.worst_expanded_um == Approx(std::sqrt(3.0) * d.best.worst_expanded_um).epsilon(1e-6));
}

TEST_CASE("effects of concern are fitted along and their correlations reported") {
  BallbarDesignOptions o;
  o.base.step_deg = 3.0;
  o.pivot_x_mm = {120.0};
  o.pivot_z_mm = {60.0};
  o.bar_lengths_mm = {100.0};
  o.effects_of_concern.effects = {Effect::parse("gravity_sag_A")};
  const BallbarDesign d = design_ballbar_test(o);
  REQUIRE(d.best.effect_vs_location.size() == 1);
  CHECK(d.best.effect_vs_location[0] > 0.0);
  CHECK(d.best.effect_vs_location[0] < 1.0);
  CHECK(d.best.names.back().find("gravity_sag_A") == 0);
  BallbarDesignOptions bad = o;
  bad.noise_rho = 1.0;
  CHECK_THROWS_WITH(design_ballbar_test(bad), Catch::Contains("--rho"));
  bad = o;
  bad.travel_max = Eigen::Vector3d(10, 10, 10);
  CHECK_THROWS_WITH(design_ballbar_test(bad), Catch::Contains("no candidate") && Catch::Contains("travel"));
}
