// SPDX-License-Identifier: BSD-3-Clause
// Tests of the R-test design (rotacal/rtest/design.hpp): the predicted 1-sigma is what
// simulated R-tests with coloured noise realise, limits and coarse grids exclude patterns by
// name, and the design beats the default pattern at the same run time.
#include <catch2/catch.hpp>
#include <cmath>
#include <map>

#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/multi/identify.hpp"
#include "rotacal/rtest/design.hpp"

using namespace rotacal;

TEST_CASE(
    "the predicted sigma of an R-test pattern is what simulated sessions with AR(1) noise "
    "realise") {
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
    const Eigen::VectorXd e =
        noise_gen::ar1(groups, times, o.noise_rho, o.noise_um * 1e-3, 900 + k);
    for (std::size_t i = 0; i < s.samples.size(); ++i)
      *s.samples[i].d += e.segment<3>(3 * static_cast<Eigen::Index>(i));
    s.noise_um = o.noise_um;
    RtestJointOptions fit;
    fit.noise.noise =
        NoiseHandling::automatic;  // AR noise model of the residuals, GLS refit, as the CLI fits
    const RtestJointIdentification id = identify_joint(s, fit);
    for (int i = 0; i < 8; ++i) est(k, i) = id.parameters[static_cast<std::size_t>(i)].value;
  }
  for (int i = 0; i < 8; ++i) {
    const Eigen::VectorXd v = est.col(i);
    const double sd = std::sqrt((v.array() - v.mean()).square().sum() / (draws - 1));
    INFO(c.names[static_cast<std::size_t>(i)] << ": realised " << sd << ", predicted "
                                              << c.sigma[i]);
    CHECK(sd / c.sigma[i] > 0.7);
    CHECK(sd / c.sigma[i] < 1.4);
  }
}

TEST_CASE(
    "the R-test design beats the default at the same run time, within travel and grid limits") {
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
  const RtestDesignCandidate twice =
      evaluate_rtest_design(d.best.pattern, o, 2.0 * d.time_budget_s);
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
  CHECK_THROWS_WITH(design_rtest_test(o),
                    Catch::Contains("no nest pair") && Catch::Contains("travel"));
}

// ------------------------------------------------------------------ separating two effects

namespace {

MachineModel oyama_like(const std::vector<Effect>& effects, const std::vector<double>& params) {
  MachineModel truth = MachineModel::nominal(MachineType::BC_trt);
  truth.errors.v << 0.02, -0.015, 3e-5, -2e-5, 0.01, 0.025, 1.5e-5, -4e-5;
  truth.effects.effects = effects;
  truth.effect_params = params;
  return truth;
}

// The readings of `truth` over `pattern` with AR(1) noise per nest and component (coloured),
// nests labelled from `first_label`, times from t0.
RtestSession recorded(const MachineModel& truth, const RtestPattern& pattern, double rho,
                      unsigned seed, int first_label = 1, double t0 = 0.0) {
  RtestSimOptions sim;
  sim.pattern = pattern;
  sim.noise_um = 0.0;
  sim.seed = seed;
  RtestSession s = simulate_rtest(truth, sim).session;
  std::vector<std::string> groups;
  std::vector<double> times;
  for (const RtestSample& x : s.samples)
    for (int a = 0; a < 3; ++a) groups.push_back(x.setup), times.push_back(x.time);
  const Eigen::VectorXd e = noise_gen::ar1(groups, times, rho, 0.3e-3, 7 * seed + 1);
  std::map<std::string, Eigen::Vector3d> nests;
  for (const auto& [label, q] : s.nests)
    nests[std::to_string(std::stoi(label) - 1 + first_label)] = q;
  s.nests = nests;
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    *s.samples[i].d += e.segment<3>(3 * static_cast<Eigen::Index>(i));
    s.samples[i].setup = std::to_string(std::stoi(s.samples[i].setup) - 1 + first_label);
    s.samples[i].time += t0;
  }
  s.noise_um = 0.3;
  return s;
}

}  // namespace

TEST_CASE("R-test: the added nest separates axial from tilt motion of C; Monte Carlo agrees") {
  const std::vector<Effect> pair = {Effect::parse("axial_motion_C_h2"),
                                    Effect::parse("tilt_motion_C_h2")};
  const MachineModel truth = oyama_like(pair, {1e-3, -0.6e-3, 2e-6, 0.0, 3e-6, -2e-6});
  const double rho = 0.4;
  const RtestPattern base;
  const RtestSession session = recorded(truth, base, rho, 3);
  const RtestSeparationDesign d = design_rtest_separation(session, pair);
  INFO(d.verdict);
  REQUIRE_FALSE(d.motion.same_motion);
  CHECK(d.correlation_before > 0.5);
  REQUIRE(d.found);
  CHECK(d.chosen.correlation < 0.5);
  CHECK(d.chosen.duration_s * d.chosen.repeats <= 600.0);
  // Monte Carlo: the session and the added nest (its grid repeated) recorded again, fitted
  // jointly with the effects by the several-session identification (white; one probe zero per
  // nest, the session's own); every determined parameter's spread against its prediction.
  RtestPattern added = d.chosen.added;
  std::vector<double> b;
  for (int r = 0; r < static_cast<int>(d.chosen.repeats); ++r)
    b.insert(b.end(), added.b_deg.begin(), added.b_deg.end());
  added.b_deg = b;
  MultiFitOptions fo;
  fo.effects.effects = pair;
  fo.noise.noise = NoiseHandling::white;
  const int draws = 80, p = static_cast<int>(d.names.size()),
            ns = static_cast<int>(session.nests.size());
  const int ne = fo.effects.num_params();
  Eigen::MatrixXd est(draws, p);
  for (int k = 0; k < draws; ++k) {
    const RtestSession first = recorded(truth, base, rho, static_cast<unsigned>(100 + k));
    const RtestSession more = recorded(truth, added, rho, static_cast<unsigned>(5000 + k), ns + 1,
                                       first.samples.back().time + 1.0);
    const MultiIdentification f = identify_multi(
        {MultiSessionInput::of("session", first), MultiSessionInput::of("added", more)}, fo);
    // The design's order: 8 location errors, the session's zeros, the effects, the added zeros.
    std::vector<ParameterEstimate> v = f.location_errors();
    for (const std::vector<ParameterEstimate>& b :
         {f.sessions[0].nuisances, f.effects(), f.sessions[1].nuisances})
      v.insert(v.end(), b.begin(), b.end());
    REQUIRE(v.size() == static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) est(k, j) = v[static_cast<std::size_t>(j)].value;
  }
  int checked = 0;
  for (int j = 0; j < p; ++j) {
    // Probe zeros are drawn anew with each simulated session (20 um): not an estimation error.
    if (!std::isfinite(d.sigma_after[j]) ||
        d.names[static_cast<std::size_t>(j)].rfind("zero_", 0) == 0)
      continue;
    const Eigen::VectorXd v = est.col(j);
    const double sd = std::sqrt((v.array() - v.mean()).square().sum() / (draws - 1));
    INFO(d.names[static_cast<std::size_t>(j)] << ": realised " << sd << ", predicted "
                                              << d.sigma_after[j]);
    CHECK(sd / d.sigma_after[j] > 0.7);
    CHECK(sd / d.sigma_after[j] < 1.4);
    ++checked;
  }
  CHECK(checked == 8 + ne);  // every location error and effect parameter is determined
}

TEST_CASE("R-test: gravity sag and the second radial harmonic of B are reported inseparable") {
  const RtestSession session = recorded(oyama_like({}, {}), RtestPattern{}, 0.2, 9);
  const RtestSeparationDesign d = design_rtest_separation(
      session, {Effect::parse("gravity_sag_B"), Effect::parse("radial_motion_B_h2")});
  CHECK(d.motion.same_motion);
  CHECK_FALSE(d.found);
  CHECK(d.candidates_tried == 0);
  CHECK(d.verdict.find("no test can separate") == 0);
  CHECK_THROWS_WITH(
      design_rtest_separation(session, {Effect::parse("gravity_sag_A"), Effect::parse("coning_B")}),
      Catch::Contains("gravity_sag_A"));
  RtestSeparationOptions bad;
  bad.max_added_time_s = 0.0;
  CHECK_THROWS_WITH(
      design_rtest_separation(session,
                              {Effect::parse("coning_B"), Effect::parse("tilt_motion_B_h1")}, bad),
      Catch::Contains("--max-time"));
}
