// SPDX-License-Identifier: BSD-3-Clause
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
#include "rotacal/core/noise_model.hpp"
#include "rotacal/multi/identify.hpp"

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
    if (seg.kind == SegmentKind::test)
      t_tests += seg.samples.back().time - seg.samples.front().time;
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
    const BallbarSession s =
        simulate_ballbar(cmd, truth, {o.noise_um, static_cast<std::uint64_t>(100 + k), true});
    const BallbarIdentification id = identify_joint(s);
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
    "travel limits exclude set-ups by name; the design beats the default at the same run time") {
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
  CHECK_THROWS_WITH(design_ballbar_test(bad),
                    Catch::Contains("no candidate") && Catch::Contains("travel"));
}

// ------------------------------------------------------------------ separating two effects

namespace {

// The Table 2 machine (shared/data/ballbar_ac_table2.truth.json) with hidden C error motions.
BallbarMachineModel hidden_machine(const BallbarSession& cmd) {
  BallbarMachineModel truth;
  truth.machine = cmd.machine;
  truth.pivot = cmd.pivot;
  truth.errors.v << 0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06,
      -4.1544e-05;
  truth.effects.effects = {Effect::parse("axial_motion_C_h2"), Effect::parse("tilt_motion_C_h2")};
  truth.effect_params = {1.0e-3, -0.6e-3, 0.0, 0.0, 3e-6, -2e-6};
  return truth;
}

// A recorded session: the exact readings of `truth` plus AR(1) noise per test (coloured).
BallbarSession recorded(const BallbarSession& cmd, BallbarMachineModel truth, double rho,
                        std::uint64_t seed) {
  truth.pivot = cmd.pivot;
  BallbarSession s = simulate_ballbar(cmd, truth, {0.0, seed, false});
  std::vector<std::string> groups;
  std::vector<double> times;
  for (const BallbarSample& x : s.samples) groups.push_back(x.test), times.push_back(x.time);
  const Eigen::VectorXd e = noise_gen::ar1(groups, times, rho, 0.5e-3, seed);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    s.samples[i].length += e[static_cast<Eigen::Index>(i)];
  s.noise_um = 0.5;  // declared, as a recorder states it: the fit's observability test uses it
  return s;
}

BallbarSession table2_command(double step_deg) {
  BallbarSetup setup;
  setup.step_deg = step_deg;
  return commanded_session(plan_ballbar_test(setup));
}

}  // namespace

TEST_CASE("the table motion decides which effects no instrument can separate") {
  // gravity sag and the second radial harmonic of the same tilt axis are one translation of
  // the table depending on the tilt angle alone, with location errors; on both machine types.
  const TableMotionOverlap ac = table_motion_overlap(
      MachineType::AC_trt, Effect::parse("gravity_sag_A"), Effect::parse("radial_motion_A_h2"));
  CHECK(ac.same_motion);
  CHECK(ac.cosine > 1.0 - 1e-6);
  CHECK(ac.why.find("no test can tell them apart") != std::string::npos);
  // ... and the sag is the special case (1 parameter of the harmonic's 4): nested, one way only
  // (the diagnosis' extended model holds the simpler one of the two when they fit alike).
  CHECK(ac.first_within_second);
  CHECK_FALSE(ac.second_within_first);
  const TableMotionOverlap ca = table_motion_overlap(
      MachineType::AC_trt, Effect::parse("radial_motion_A_h2"), Effect::parse("gravity_sag_A"));
  CHECK(ca.second_within_first);
  CHECK_FALSE(ca.first_within_second);
  const TableMotionOverlap bc = table_motion_overlap(
      MachineType::BC_trt, Effect::parse("gravity_sag_B"), Effect::parse("radial_motion_B_h2"));
  CHECK(bc.same_motion);
  // The third harmonic holds none of the sag's 1 - cos A: a test can separate those.
  const TableMotionOverlap h3 = table_motion_overlap(
      MachineType::AC_trt, Effect::parse("gravity_sag_A"), Effect::parse("radial_motion_A_h3"));
  CHECK_FALSE(h3.same_motion);
  CHECK(h3.cosine < 0.9);
  CHECK_FALSE(h3.first_within_second);
  CHECK_FALSE(h3.second_within_first);
  // The axial and tilt motions of C differ by the lever arm of the table point.
  const TableMotionOverlap c2 = table_motion_overlap(
      MachineType::AC_trt, Effect::parse("axial_motion_C_h2"), Effect::parse("tilt_motion_C_h2"));
  CHECK_FALSE(c2.same_motion);
  // A zero offset of the tilt axis and its first positioning harmonic: different motions.
  CHECK_FALSE(table_motion_overlap(MachineType::AC_trt, Effect::parse("rotary_zero_offset_A"),
                                   Effect::parse("angular_positioning_A_h1"))
                  .same_motion);
  // A tool-side effect does not move the table: the table motion cannot decide.
  const TableMotionOverlap tool = table_motion_overlap(
      MachineType::AC_trt, Effect::parse("tool_offset_Z"), Effect::parse("axial_motion_C_h2"));
  CHECK_FALSE(tool.moves_table_first);
  CHECK_FALSE(tool.same_motion);
  CHECK_THROWS_WITH(table_motion_overlap(MachineType::AC_trt, Effect::parse("gravity_sag_B"),
                                         Effect::parse("radial_motion_A_h2")),
                    Catch::Contains("gravity_sag_B"));
}

namespace {

// The separation the two cases below study: a session of the Table 2 machine with hidden C
// error motions in AR(1) noise, the design of a test that separates them, and that test as
// run (slower by the design's factor, after the session).
struct SeparationStudy {
  BallbarSession cmd;
  BallbarMachineModel truth;
  double rho = 0.5;
  BallbarSession session;
  std::vector<Effect> pair;
  SeparationDesign d;
  BallbarSession added_cmd;
};

SeparationStudy separation_study() {
  SeparationStudy st;
  st.cmd = table2_command(2.0);
  st.truth = hidden_machine(st.cmd);
  st.session = recorded(st.cmd, st.truth, st.rho, 7);
  st.pair = {Effect::parse("axial_motion_C_h2"), Effect::parse("tilt_motion_C_h2")};
  SeparationOptions o;
  o.added.step_deg = 2.0;
  st.d = design_ballbar_separation(st.session, st.pair, o);
  if (st.d.found) {
    BallbarSetup added = st.d.chosen.setup;
    added.step_deg /= st.d.chosen.slow_down;
    st.added_cmd = commanded_session(plan_ballbar_test(added));
    for (BallbarSample& s : st.added_cmd.samples) s.time += st.session.samples.back().time;
  }
  return st;
}

// What the design states of that separation: found, short enough, no sigma made worse.
void check_separation_design(const SeparationDesign& d) {
  INFO(d.verdict);
  REQUIRE_FALSE(d.motion.same_motion);
  CHECK(d.correlation_before > 0.85);
  REQUIRE(d.found);
  CHECK(d.chosen.correlation < 0.5);
  CHECK(d.chosen.duration_s * d.chosen.slow_down <= 600.0);
  // The noise model of the session: AR(1) with rho 0.5 leaves about 1/3 effective readings.
  CHECK(d.effective_per_reading == Approx(1.0 / 3.0).epsilon(0.35));
  const int first = 11, ne = 6;
  for (int j = first; j < first + ne; ++j)
    CHECK(d.sigma_after[j] <= d.sigma_before[j] * (1 + 1e-9));
  for (int j = 0; j < 8; ++j) CHECK(std::isfinite(d.sigma_after[j]));
}

// The session and the added test fitted jointly by the several-session identification
// (multi/identify.hpp), white: the location errors and the pair shared, and the pivot too
// unless the design moved it (the ball stayed in its cup).
MultiIdentification fitted_jointly(const SeparationStudy& st, const BallbarSession& first,
                                   const BallbarSession& added) {
  MultiFitOptions o;
  o.effects.effects = st.pair;
  o.noise.noise = NoiseHandling::white;
  MultiSessionInput more = MultiSessionInput::of("added", added);
  if (!st.d.chosen.new_pivot) more.same_setup_as = "session";
  return identify_multi({MultiSessionInput::of("session", first), more}, o);
}

// Its estimates in the design's order: 8 location errors, the session's pivot, the pair's
// parameters, the moved pivot (the added session's own; else it reports the session's).
std::vector<ParameterEstimate> in_design_order(const MultiIdentification& f, bool moved) {
  std::vector<ParameterEstimate> out = f.location_errors();
  for (const std::vector<ParameterEstimate>& b :
       {f.sessions[0].nuisances, f.effects(),
        moved ? f.sessions[1].nuisances : std::vector<ParameterEstimate>{}})
    out.insert(out.end(), b.begin(), b.end());
  return out;
}

}  // namespace

TEST_CASE(
    "one draw of the session and the added test, fitted jointly: the design's parameters "
    "and their uncertainty") {
  const SeparationStudy st = separation_study();
  const SeparationDesign& d = st.d;
  check_separation_design(d);
  EffectModel fx;
  fx.effects = st.pair;
  const int ne = 6;
  const int p = static_cast<int>(d.names.size());
  const BallbarSession first = recorded(st.cmd, st.truth, st.rho, 1000);
  JointFitOptions white;
  white.effects = fx;
  const std::vector<ParameterEstimate> alone = identify_joint(first, white).parameters;
  const MultiIdentification joint =
      fitted_jointly(st, first, recorded(st.added_cmd, st.truth, st.rho, 5000));
  const std::vector<ParameterEstimate> f = in_design_order(joint, st.d.chosen.new_pivot);
  REQUIRE(joint.converged);
  REQUIRE(alone.size() == 11 + ne);
  REQUIRE(f.size() == static_cast<std::size_t>(p));
  Eigen::VectorXd truth(11 + ne);
  truth << st.truth.errors.v, st.cmd.pivot,
      Eigen::Map<const Eigen::VectorXd>(st.truth.effect_params.data(), ne);
  for (std::size_t j = 0; j < f.size(); ++j) {
    const double predicted = d.sigma_after[static_cast<Eigen::Index>(j)];
    INFO(d.names[j] << " (fit: " << f[j].name << "): " << f[j].value << " jointly, predicted sigma "
                    << predicted);
    // The moved pivot is the added session's own "pivot_x"; the design calls it "pivot_x#2".
    CHECK(f[j].name + (j >= 11u + ne ? "#2" : "") == d.names[j]);
    CHECK(std::isfinite(f[j].value));
    // The parameters the design holds, the fit holds (a zero sigma); the others it determines.
    CHECK((f[j].std > 0.0) == std::isfinite(predicted));
    if (j >= 11u + ne || !std::isfinite(predicted)) continue;
    // One draw from the truth: within 5 predicted sigma, jointly and from the session alone.
    const Eigen::Index i = static_cast<Eigen::Index>(j);
    CHECK(std::abs(f[j].value - truth[i]) < 5.0 * predicted);
    if (std::isfinite(d.sigma_before[i]))
      CHECK(std::abs(alone[j].value - truth[i]) < 5.0 * d.sigma_before[i]);
  }
  // The fits' own covariances (white: the noise's colour scales both alike) shrink the pair's
  // sigma by the factor the design predicts (within 0.1 % on this draw).
  for (int j = 11; j < 11 + ne; ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    if (!std::isfinite(d.sigma_before[j]) || !std::isfinite(d.sigma_after[j])) continue;
    const double realised = f[k].std / alone[k].std;
    const double predicted = d.sigma_after[j] / d.sigma_before[j];
    INFO(d.names[static_cast<std::size_t>(j)] << ": sigma ratio " << realised << ", predicted "
                                              << predicted);
    CHECK(realised == Approx(predicted).epsilon(0.05));
  }
}

TEST_CASE("the added test separates axial and tilt motion of C; its predicted sigma is realised",
          "[statistical]") {
  const SeparationStudy st = separation_study();
  const SeparationDesign& d = st.d;
  check_separation_design(d);
  const BallbarSession& cmd = st.cmd;
  const BallbarMachineModel& truth = st.truth;
  const double rho = st.rho;

  // Monte Carlo: new noise on the session and on the added test (run slower: s times the
  // readings), both fitted jointly; the spread of the estimates against the prediction.
  EffectModel fx;
  fx.effects = st.pair;
  const int draws = 80;
  const int p = static_cast<int>(d.names.size());
  Eigen::MatrixXd est(draws, p);
  for (int k = 0; k < draws; ++k) {
    const MultiIdentification f = fitted_jointly(st, recorded(cmd, truth, rho, 1000 + k),
                                                 recorded(st.added_cmd, truth, rho, 5000 + k));
    REQUIRE(f.converged);
    const std::vector<ParameterEstimate> v = in_design_order(f, st.d.chosen.new_pivot);
    REQUIRE(v.size() == static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) est(k, j) = v[static_cast<std::size_t>(j)].value;
  }
  for (int j = 0; j < p; ++j) {
    if (!std::isfinite(d.sigma_after[j])) continue;  // held by the design: the fit holds it too
    const Eigen::VectorXd v = est.col(j);
    const double sd = std::sqrt((v.array() - v.mean()).square().sum() / (draws - 1));
    INFO(d.names[static_cast<std::size_t>(j)] << ": realised " << sd << ", predicted "
                                              << d.sigma_after[j]);
    CHECK(sd / d.sigma_after[j] > 0.7);
    CHECK(sd / d.sigma_after[j] < 1.4);
  }
}

TEST_CASE("gravity sag and the second radial harmonic of A: no test is proposed, and why") {
  const BallbarSession cmd = table2_command(3.0);
  BallbarMachineModel truth = hidden_machine(cmd);
  truth.effects.effects.clear();
  truth.effect_params.clear();
  const BallbarSession session = recorded(cmd, truth, 0.3, 11);
  const SeparationDesign d = design_ballbar_separation(
      session, {Effect::parse("gravity_sag_A"), Effect::parse("radial_motion_A_h2")});
  CHECK(d.motion.same_motion);
  CHECK_FALSE(d.found);
  CHECK(d.candidates_tried == 0);
  CHECK(d.verdict.find("no test can separate gravity_sag_A and radial_motion_A_h2") == 0);
  // Bad input names the option.
  CHECK_THROWS_WITH(design_ballbar_separation(session, {Effect::parse("gravity_sag_A")}),
                    Catch::Contains("--separate"));
  SeparationOptions bad;
  bad.max_correlation = 1.0;
  CHECK_THROWS_WITH(
      design_ballbar_separation(
          session, {Effect::parse("axial_motion_C_h2"), Effect::parse("tilt_motion_C_h2")}, bad),
      Catch::Contains("--max-correlation"));
  bad = SeparationOptions{};
  bad.pivot_z_mm.clear();
  CHECK_THROWS_WITH(
      design_ballbar_separation(
          session, {Effect::parse("axial_motion_C_h2"), Effect::parse("tilt_motion_C_h2")}, bad),
      Catch::Contains("--pivot-z"));
}
