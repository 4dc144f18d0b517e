// SPDX-License-Identifier: BSD-3-Clause
// Tests of the ballbar Monte Carlo: same draws as simulate_ballbar + identify_joint, spread
// against the reported sigma, a coloured-noise generator plugged in, refusals.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "rotacal/ballbar/identify_paper.hpp"
#include "rotacal/ballbar/monte_carlo.hpp"
#include "rotacal/ballbar/plan.hpp"
#include "rotacal/ballbar/simulate.hpp"

using namespace rotacal;

namespace {
// A measured-looking session: Table-2-sized errors, a pivot set-up error, a gravity sag the
// fit models, and noise.
struct Fixture {
  BallbarSession session;
  BallbarIdentification id;
  JointFitOptions fit;
  Fixture() {
    BallbarSetup setup;
    setup.machine = MachineType::AC_trt;
    setup.step_deg = 3.0;
    const BallbarSession cmd = commanded_session(plan_ballbar_test(setup));
    BallbarMachineModel t;
    t.machine = MachineType::AC_trt;
    t.errors.v << 0.01, -0.02, 3e-5, -2e-5, 0.015, 0.013, 1e-5, -4e-5;
    t.pivot = cmd.pivot + Eigen::Vector3d(0.03, -0.02, 0.01);
    t.effects.effects = {Effect::parse("gravity_sag_A")};
    t.effect_params = {0.004};
    session = simulate_ballbar(cmd, t, {0.5, 7, true});
    fit.effects = t.effects;
    id = identify_joint(session, fit);
  }
};
}  // namespace

TEST_CASE("Monte Carlo draws are those of simulate_ballbar and refits match fresh fits",
          "[monte_carlo]") {
  const Fixture f;
  REQUIRE(f.id.converged);
  BallbarMonteCarloOptions o;
  o.draws = 4;
  o.seed = 40;
  const BallbarMonteCarlo mc = monte_carlo(f.session, f.id, o);
  CHECK(mc.fresh_fits == 0);
  CHECK(mc.noise_um == Approx(f.id.sigma_um));
  for (int k = 0; k < o.draws; ++k) {
    const BallbarSession sim =
        simulate_ballbar(f.session, f.id.model, {f.id.sigma_um, o.seed + k, true});
    const BallbarIdentification fresh = identify_joint(sim, f.fit);
    for (std::size_t j = 0; j < fresh.parameters.size(); ++j) {
      INFO("draw " << k << " " << fresh.parameters[j].name);
      CHECK(std::abs(mc.values(k, static_cast<Eigen::Index>(j)) - fresh.parameters[j].value) <=
            1e-3 * fresh.parameters[j].std);
    }
  }
}

TEST_CASE("Monte Carlo spread matches the reported sigma on white noise", "[monte_carlo]") {
  const Fixture f;
  BallbarMonteCarloOptions o;
  o.draws = 400;  // relative error of a spread: 1/sqrt(2 * 400) = 3.5 %
  int calls = 0;
  bool ordered = true;
  o.progress = [&](int done, int total) { ordered = ordered && done == ++calls && total == 400; };
  const BallbarMonteCarlo mc = monte_carlo(f.session, f.id, o);
  CHECK(calls == 400);
  CHECK(ordered);
  REQUIRE(mc.parameters.size() == f.id.parameters.size());  // all observable here
  for (const MonteCarloParameter& p : mc.parameters) {
    INFO(p.name << ": ratio " << p.ratio << ", bias " << p.bias << " " << p.unit);
    CHECK(p.ratio == Approx(1.0).margin(0.15));
    CHECK(std::abs(p.bias) <= 0.25 * p.std_reported);  // 5 sigma of a mean over 400 draws
  }
}

TEST_CASE("a coloured noise generator shows the white fit's sigma to be optimistic",
          "[monte_carlo]") {
  const Fixture f;
  BallbarMonteCarloOptions o;
  o.draws = 200;
  const double phi = 0.9, s = 0.5e-3 * std::sqrt(1 - phi * phi);  // 0.5 um marginal
  o.noise = [&](int k, Eigen::Ref<Eigen::VectorXd> e) {
    std::mt19937_64 rng(1000 + static_cast<std::uint64_t>(k));
    std::normal_distribution<double> N(0.0, 1.0);
    e[0] = 0.5e-3 * N(rng);
    for (Eigen::Index i = 1; i < e.size(); ++i) e[i] = phi * e[i - 1] + s * N(rng);
  };
  const BallbarMonteCarlo mc = monte_carlo(f.session, f.id, o);
  double worst = 0.0;
  for (const MonteCarloParameter& p : mc.parameters) worst = std::max(worst, p.ratio);
  CHECK(worst > 2.0);  // (1 + phi) / (1 - phi) = 19: slowly varying parameters far off
}

TEST_CASE("Monte Carlo refuses what it cannot check", "[monte_carlo]") {
  const Fixture f;
  BallbarMonteCarloOptions o;
  o.draws = 1;
  CHECK_THROWS_WITH(monte_carlo(f.session, f.id, o), Catch::Contains("draws"));
  o.draws = 10;
  o.noise_um = -1.0;
  CHECK_THROWS_WITH(monte_carlo(f.session, f.id, o), Catch::Contains("noise_um"));
  o.noise_um = 0.0;
  CHECK_THROWS_WITH(monte_carlo(f.session, identify_paper(f.session), o), Catch::Contains("joint"));
  o.fit.tests = {f.session.samples.front().test};
  CHECK_THROWS_WITH(monte_carlo(f.session, f.id, o), Catch::Contains("samples"));
}
