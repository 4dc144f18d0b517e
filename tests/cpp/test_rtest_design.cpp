// Tests of the R-test design (rotacal/rtest/design.hpp): the predicted 1-sigma is what
// simulated R-tests with coloured noise realise, limits and coarse grids exclude patterns by
// name, and the design beats the default pattern at the same run time.
#include <catch2/catch.hpp>

#include <cmath>

#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/rtest/design.hpp"

using namespace rotacal;

TEST_CASE("the predicted sigma of an R-test pattern is what simulated sessions with AR(1) noise realise") {
  RtestDesignOptions o;
  o.noise_um = 0.3;
  o.noise_rho = 0.4;
  // The default pattern, and one with C every 60 deg (successive poses far apart: AR noise
  // costs less there than slowly varying readings would suggest).
  RtestPattern coarse = o.base;
  coarse.nests = {Eigen::Vector3d(150, 0, 100), Eigen::Vector3d(0, -150, 20)};
  coarse.b_deg = {-90, -75, -60, -45, -30, -15, 0, 15, 30, 45, 60, 75, 90};
  coarse.c_deg = {0, 60, 120, 180, 240, 300};
  const RtestPattern pattern = GENERATE_COPY(o.base, coarse);
  o.base = pattern;
  const RtestDesignCandidate c = evaluate_rtest_design(o.base, o, 0.0);
  REQUIRE(c.feasible);
  // A machine with location errors of the size Oyama and Ibaraki report (mm, rad).
  MachineModel truth = MachineModel::nominal(MachineType::BC_trt);
  truth.errors.v << 0.02, -0.015, 3e-5, -2e-5, 0.01, 0.025, 1.5e-5, -4e-5;
  const int draws = 60;
  Eigen::MatrixXd est(draws, 8);
  for (int k = 0; k < draws; ++k) {
    RtestSimOptions sim;
    sim.pattern = o.base;
    sim.noise_um = 0.0;
    sim.seed = static_cast<unsigned>(100 + k);
    RtestSession s = simulate_rtest(truth, sim).session;
    // Coloured noise per nest and component, in time order.
    std::vector<std::string> groups;
    std::vector<double> times;
    for (const RtestSample& x : s.samples)
      for (int a = 0; a < 3; ++a) groups.push_back(x.setup), times.push_back(x.time);
    const Eigen::VectorXd e = noise_gen::ar1(groups, times, o.noise_rho, o.noise_um * 1e-3, 900 + k);
    for (std::size_t i = 0; i < s.samples.size(); ++i)
      *s.samples[i].d += e.segment<3>(3 * static_cast<Eigen::Index>(i));
    s.noise_um = o.noise_um;
    RtestJointOptions fit;
    fit.noise = NoiseHandling::automatic;  // AR noise model of the residuals, GLS refit, as the CLI fits
    const RtestJointIdentification id = identify_joint(s, fit);
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

TEST_CASE("the R-test design beats the default at the same run time, within travel and grid limits") {
  RtestDesignOptions o;
  o.nest_radius_mm = {50.0, 150.0};
  o.nest_height_mm = {20.0, 100.0, 140.0};
  o.b_step_deg = {30.0, 45.0};
  o.c_step_deg = {30.0, 60.0};
  o.travel_max.z() = 190.0;  // a nest 150 mm out and 140 mm up reaches Z = 196 mm at B = 30 deg
  const RtestDesign d = design_rtest_test(o);
  REQUIRE(d.baseline.feasible);
  REQUIRE(d.best.feasible);
  CHECK(d.time_budget_s == Approx(d.baseline.duration_s));
  CHECK(d.best.duration_s <= d.time_budget_s);
  CHECK(d.best.worst_expanded_um < d.baseline.worst_expanded_um);
  CHECK(d.ratio == Approx(d.best.worst_expanded_um / d.baseline.worst_expanded_um));
  bool by_travel = false, by_grid = false;
  for (const RtestDesignCandidate& c : d.candidates) {
    if (c.feasible) continue;
    by_travel |= c.why_not.find("Z = ") == 0;
    by_grid |= c.why_not.find("too coarse") != std::string::npos;
  }
  CHECK(by_travel);
  CHECK(by_grid);  // B every 45 deg cannot carry the B map of degree 6
  // Twice the time, sigma / sqrt(2). AR(1) noise with rho 0.5 costs information, at most
  // the (1 + rho) / (1 - rho) = 3 of slowly varying readings in variance.
  const RtestDesignCandidate twice = evaluate_rtest_design(d.best.pattern, o, 2.0 * d.time_budget_s);
  CHECK(twice.worst_expanded_um == Approx(d.best.worst_expanded_um / std::sqrt(2.0)).epsilon(1e-6));
  RtestDesignOptions ar = o;
  ar.noise_rho = 0.5;
  const double u_ar = evaluate_rtest_design(d.best.pattern, ar, d.time_budget_s).worst_expanded_um;
  CHECK(u_ar > 1.05 * d.best.worst_expanded_um);
  CHECK(u_ar < std::sqrt(3.0) * d.best.worst_expanded_um * (1 + 1e-6));
  // Over the budget: refused by name.
  const RtestDesignCandidate over = evaluate_rtest_design(o.base, o, 100.0);
  CHECK_FALSE(over.feasible);
  CHECK(over.why_not.find("time budget") != std::string::npos);
}

TEST_CASE("R-test design options are refused by name") {
  RtestDesignOptions o;
  o.noise_rho = 1.0;
  CHECK_THROWS_WITH(design_rtest_test(o), Catch::Contains("--rho"));
  o = RtestDesignOptions{};
  o.c_step_deg = {0.0};
  CHECK_THROWS_WITH(design_rtest_test(o), Catch::Contains("--c-steps"));
  o = RtestDesignOptions{};
  o.nest_height_mm.clear();
  CHECK_THROWS_WITH(design_rtest_test(o), Catch::Contains("--heights"));
  o = RtestDesignOptions{};
  o.travel_max = Eigen::Vector3d(10, 10, 10);
  CHECK_THROWS_WITH(design_rtest_test(o), Catch::Contains("no nest pair") && Catch::Contains("travel"));
}
