// SPDX-License-Identifier: BSD-3-Clause
// One identification from a ballbar and a touch-probe session of one AC-trt machine
// (multi/identify.hpp): the joint values lie within 3 sigma of the simulated machine, the joint
// sigma is no larger than either session's alone, a session of another machine is refused by
// name, a session whose machine differs by 30 um in one error is reported as disagreeing, a shared
// effect is fitted once, the block-diagonal whitener whitens each session by its own model, and
// a session that continues another's set-up shares its pivot.
#include <catch2/catch.hpp>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/block_whitener.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/multi/identify.hpp"
#include "rotacal/probe/simulate.hpp"

using namespace rotacal;

namespace {
// The machine of both sessions: several location errors at once.
MachineModel machine_truth() {
  MachineModel t = MachineModel::nominal(MachineType::AC_trt);
  t.errors.v << 0.03, -0.02, 2e-5, -3e-5, 0.01, 0.04, -1e-5, 2e-5;
  return t;
}

BallbarSession ballbar_session(const MachineModel& t, std::uint64_t seed) {
  BallbarSetup setup;
  setup.machine = t.machine;
  const BallbarSession cmd = commanded_session(plan_ballbar_test(setup));
  BallbarMachineModel b;
  static_cast<MachineModel&>(b) = t;
  b.pivot = cmd.pivot + Eigen::Vector3d(0.02, -0.01, 0.015);
  return simulate_ballbar(cmd, b, {0.5, seed, true});
}

ProbeSession probe_session(const MachineModel& t, std::uint64_t seed) {
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(t.machine);
  o.sphere_offset = Eigen::Vector3d(0.04, -0.03, 0.02);
  o.noise_um = 0.5;
  o.ar1_rho = 0.6;
  o.seed = seed;
  return simulate_probe(t, o).session;
}
}  // namespace

TEST_CASE("ballbar + probe of one machine: joint values within 3 sigma, sigma no larger than alone",
          "[multi]") {
  const MachineModel t = machine_truth();
  const MultiIdentification id =
      identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 11)),
                      MultiSessionInput::of("probe", probe_session(t, 12))});
  CHECK(id.converged);
  REQUIRE(id.sessions.size() == 2);
  CHECK(id.disagreements.empty());
  const auto& names = location_error_names(MachineType::AC_trt);
  int observed = 0;
  for (std::size_t j = 0; j < names.size(); ++j) {
    const ParameterEstimate& p = id.location_error(names[j]);
    INFO(p.name << " = " << p.value << " +- " << p.std << ", truth "
                << t.errors.v[static_cast<Eigen::Index>(j)]);
    if (!p.observable) continue;
    ++observed;
    CHECK(std::abs(p.value - t.errors.v[static_cast<Eigen::Index>(j)]) <= 3.0 * p.std);
    for (const MultiSessionResult& s : id.sessions) {
      const ParameterEstimate& a = s.alone[j];
      INFO(s.name << " alone: " << a.value << " +- " << a.std);
      if (a.observable) CHECK(p.std <= a.std * 1.0001);
    }
  }
  CHECK(observed == 8);
  // Each session keeps its own nuisances: the ballbar's pivot, the probe's sphere.
  CHECK(id.sessions[0].nuisances.size() == 3);
  CHECK(id.sessions[0].nuisances[0].name == "pivot_x");
  CHECK(id.sessions[1].nuisances.size() == 3);
  CHECK(id.sessions[1].noise_refit);  // AR(1) touches: the probe's rows are whitened by its model
}

TEST_CASE("a session whose machine differs by 30 um is reported as disagreeing", "[multi]") {
  const MachineModel t = machine_truth();
  MachineModel moved = t;
  const auto& names = location_error_names(MachineType::AC_trt);
  moved.errors.v[4] += 0.030;  // one location error of the probe's machine, 30 um off
  const MultiIdentification id =
      identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 21)),
                      MultiSessionInput::of("probe", probe_session(moved, 22))});
  REQUIRE(!id.disagreements.empty());
  bool found = false;
  for (const MultiDisagreement& d : id.disagreements) {
    INFO(d.parameter << " " << d.session_a << " vs " << d.session_b << ": " << d.difference
                     << " +- " << d.sigma);
    CHECK(std::abs(d.z) > 3.0);
    CHECK(std::abs(d.z - d.difference / d.sigma) < 1e-9);
    if (d.parameter == names[4]) {
      found = true;
      CHECK(d.session_a == "bb");
      CHECK(d.session_b == "probe");
      CHECK(d.difference == Approx(-0.030).margin(3.0 * d.sigma));
    }
  }
  CHECK(found);
}

TEST_CASE("sessions of different machine types are refused by name", "[multi]") {
  const MachineModel t = machine_truth();
  MachineModel other = MachineModel::nominal(MachineType::BC_trt);
  try {
    identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 1)),
                    MultiSessionInput::of("probe-bc", probe_session(other, 2))});
    FAIL("no exception");
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    CHECK(what.find("bb") != std::string::npos);
    CHECK(what.find("probe-bc") != std::string::npos);
  }
  CHECK_THROWS_AS(identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 1))}),
                  InvalidArgument);
}

TEST_CASE("a catalogue effect shared by both sessions is fitted once, within 3 sigma", "[multi]") {
  MachineModel t = machine_truth();
  t.effects = EffectModel{{Effect::parse("gravity_sag_A")}, std::nullopt};
  t.effect_params = {0.004};
  MultiFitOptions o;
  o.effects = EffectModel{{Effect::parse("gravity_sag_A")}, std::nullopt};
  const MultiIdentification id =
      identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 31)),
                      MultiSessionInput::of("probe", probe_session(t, 32))},
                     o);
  CHECK(id.converged);
  const std::vector<ParameterEstimate> sag = id.effects();
  REQUIRE(sag.size() == 1);
  INFO("gravity_sag_A = " << sag[0].value << " +- " << sag[0].std);
  CHECK(sag[0].observable);
  CHECK(sag[0].std < 0.0005);  // determined, not merely within a wide sigma
  CHECK(std::abs(sag[0].value - 0.004) <= 3.0 * sag[0].std);
  const auto& names = location_error_names(MachineType::AC_trt);
  for (std::size_t j = 0; j < names.size(); ++j) {
    const ParameterEstimate p = id.location_errors()[j];
    INFO(p.name << " = " << p.value << " +- " << p.std);
    if (p.observable)
      CHECK(std::abs(p.value - t.errors.v[static_cast<Eigen::Index>(j)]) <= 3.0 * p.std);
  }
  for (const MultiSessionResult& s : id.sessions) {
    REQUIRE(s.alone.size() ==
            9);  // the location errors, then the shared effect, each session alone
    CHECK(s.alone[8].name == "gravity_sag_A");
    for (const ParameterEstimate& n : s.nuisances) CHECK(n.name != "gravity_sag_A");
  }
}

TEST_CASE("the block-diagonal whitener whitens each session's rows by its own model", "[multi]") {
  // Block 1: 1 / sigma = 2 (white, 2 rows); block 2: an AR whitener of 3 rows, then factor 0.5.
  NoiseModel white3;
  const std::vector<std::string> g(3, "s");
  const std::vector<double> t{0.0, 1.0, 2.0};
  white3 = estimate_noise_model(g, t, Eigen::Vector3d(0.1, -0.2, 0.15), NoiseModelOptions{});
  auto ar = std::make_shared<ArWhitener>(white3);
  const BlockDiagonalWhitener W({{2, nullptr, 2.0}, {3, ar, 0.5}});
  CHECK(W.size() == 5);
  Eigen::MatrixXd c = Eigen::MatrixXd::Ones(5, 2);
  Eigen::MatrixXd lower = Eigen::MatrixXd::Ones(3, 2);
  ar->apply(lower);
  W.apply(c);
  CHECK(c.topRows(2).isApprox(Eigen::MatrixXd::Constant(2, 2, 2.0)));
  CHECK(c.bottomRows(3).isApprox(0.5 * lower));
  CHECK_THROWS_AS(BlockDiagonalWhitener({{4, ar, 1.0}}),
                  InvalidArgument);  // 3-row whitener on 4 rows
  CHECK_THROWS_AS(BlockDiagonalWhitener({{2, nullptr, 0.0}}), InvalidArgument);
}

TEST_CASE("white noise handling weights each session by its own residual sigma", "[multi]") {
  const MachineModel t = machine_truth();
  MultiFitOptions o;
  o.noise.noise = NoiseHandling::white;
  const MultiIdentification id =
      identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 41)),
                      MultiSessionInput::of("probe", probe_session(t, 42))},
                     o);
  CHECK(id.converged);
  for (const MultiSessionResult& s : id.sessions) CHECK_FALSE(s.noise_refit);
  // Whitened to unit variance per session: the joint chi2/dof is near 1.
  CHECK(id.summary.chi2_per_dof == Approx(1.0).margin(0.1));
  for (std::size_t j = 0; j < 8; ++j) {
    const ParameterEstimate p = id.location_errors()[j];
    if (p.observable)
      CHECK(std::abs(p.value - t.errors.v[static_cast<Eigen::Index>(j)]) <= 3.0 * p.std);
  }
}

TEST_CASE("a session that continues another's set-up shares its pivot, fitted once", "[multi]") {
  const MachineModel t = machine_truth();
  MultiFitOptions o;
  o.noise.noise = NoiseHandling::white;
  MultiSessionInput added = MultiSessionInput::of("added", ballbar_session(t, 52));
  const MultiIdentification apart =
      identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 51)), added}, o);
  added.same_setup_as = "bb";
  const MultiIdentification shared =
      identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 51)), added}, o);
  CHECK(apart.parameters.size() == 8 + 3 + 3);
  REQUIRE(shared.parameters.size() == 8 + 3);
  CHECK(shared.block("bb").size() == 3);
  CHECK(shared.block("added").empty());
  // Both sessions report the one pivot as their own.
  const Eigen::Vector3d truth = commanded_session(plan_ballbar_test(BallbarSetup{})).pivot +
                                Eigen::Vector3d(0.02, -0.01, 0.015);
  for (int k = 0; k < 3; ++k) {
    const ParameterEstimate &a = shared.sessions[0].nuisances[static_cast<std::size_t>(k)],
                            &b = shared.sessions[1].nuisances[static_cast<std::size_t>(k)];
    INFO(a.name << " = " << a.value << " +- " << a.std << ", truth " << truth[k]);
    CHECK(b.name == a.name);
    CHECK(b.value == a.value);
    CHECK(std::abs(a.value - truth[k]) <= 3.0 * a.std);
    // Twice the readings of one pivot: its sigma about 1/sqrt(2) of either session's own.
    CHECK(a.std < 0.85 * apart.sessions[0].nuisances[static_cast<std::size_t>(k)].std);
  }
  added.same_setup_as = "probe";
  CHECK_THROWS_WITH(identify_multi({MultiSessionInput::of("bb", ballbar_session(t, 51)), added}, o),
                    Catch::Contains("added") && Catch::Contains("no earlier ballbar session"));
  MultiSessionInput first = MultiSessionInput::of("bb", ballbar_session(t, 51));
  first.same_setup_as = "added";  // a later session: not continued
  CHECK_THROWS_WITH(identify_multi({first, MultiSessionInput::of("added", ballbar_session(t, 52))}),
                    Catch::Contains("no earlier ballbar session"));
}
