// SPDX-License-Identifier: BSD-3-Clause
// Tests of the uncertainty budget: the type B line of a left-out effect equals the shift that
// effect really puts on a location error (nonlinear refit of a simulated session), the GUM
// arithmetic (combined, Welch-Satterthwaite, coverage), overrides, and bad input.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"
#include "rotacal/diagnose/ballbar_diagnosis.hpp"
#include "rotacal/diagnose/uncertainty_budget.hpp"
#include "rotacal/io/ballbar_file.hpp"

using namespace rotacal;

namespace {
const BallbarSession& commanded() {
  static const BallbarSession s =
      read_ballbar(std::string(ROTACAL_SHARED_DIR) + "/data/ballbar_ac_table2.csv");
  return s;
}
BallbarMachineModel machine() {
  BallbarMachineModel m;
  m.machine = MachineType::AC_trt;
  std::mt19937 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int i = 0; i < 8; ++i)
    m.errors.v[i] = location_error_is_angle(i) ? 5e-5 * N(rng) : 0.03 * N(rng);
  m.pivot = commanded().pivot;
  return m;
}
const LocationBudget& line_of(const UncertaintyBudget& B, const std::string& name) {
  for (const LocationBudget& L : B.errors)
    if (L.name == name) return L;
  throw std::runtime_error("no " + name);
}
}  // namespace

TEST_CASE("a left-out X/Y squareness of 20 urad: the budget line is the shift it puts on E_C0A",
          "[budget]") {
  const BallbarMachineModel truth = machine();
  const BallbarSession clean = simulate_ballbar(commanded(), truth, {0.5, 11, true});
  BallbarDiagnosisProblem P(clean);
  const Diagnosis D = diagnose(P);
  REQUIRE(D.findings.empty());
  const UncertaintyBudget B = uncertainty_budget(P, D);
  const LocationBudget& c0a = line_of(B, "E_C0A");
  REQUIRE(c0a.observable);
  const auto it = std::find_if(c0a.type_b.begin(), c0a.type_b.end(), [](const BudgetLine& b) {
    return b.effect == "linear_squareness_XY";
  });
  REQUIRE(it != c0a.type_b.end());
  // Independent: hide 20 urad of squareness in a noise-free session, refit the baseline
  // (nonlinear), and see how far E_C0A moves.
  BallbarMachineModel with = truth;
  with.effects.effects = {Effect::parse("linear_squareness_XY")};
  with.effect_params = {20e-6};
  BallbarSession s = simulate_ballbar(commanded(), with, {0.0, 1, false});
  s.noise_um = 0.5;
  const ModelFit refit = BallbarDiagnosisProblem(s).fit(EffectModel{});
  const double shift =
      std::abs(refit
                   .parameters[static_cast<std::size_t>(
                       std::find(location_error_names(MachineType::AC_trt).begin(),
                                 location_error_names(MachineType::AC_trt).end(), "E_C0A") -
                       location_error_names(MachineType::AC_trt).begin())]
                   .value -
               truth.errors.v[static_cast<Eigen::Index>(
                   std::find(location_error_names(MachineType::AC_trt).begin(),
                             location_error_names(MachineType::AC_trt).end(), "E_C0A") -
                   location_error_names(MachineType::AC_trt).begin())]);
  INFO("shift of E_C0A " << shift * 1e6 << " urad; budget line " << it->bias_at_size * 1e6
                         << " urad at " << it->basis);
  // The statement: about 20 urad.
  CHECK(shift > 10e-6);
  CHECK(shift < 30e-6);
  // The line is the linearised shift at its half-width: 20 urad by default, or the session's
  // tighter bound (this session sees some of the squareness beyond what E_C0A absorbs).
  REQUIRE(it->half_width.size() == 1);
  CHECK(it->half_width[0] <= 20e-6);
  CHECK(it->bias_at_size == Approx(shift * it->half_width[0] / 20e-6).epsilon(0.03));
  CHECK(it->u == Approx(it->bias_at_size / std::sqrt(3.0)).epsilon(1e-12));
  // Without the session's bounds (defaults only), the line is the full 20 urad and a user who
  // has not calibrated the linear axes sees it among the dominant ones.
  PlausibleSizes defaults;
  defaults.use_session_bounds = false;
  const UncertaintyBudget B_default = uncertainty_budget(P, D, defaults);
  const LocationBudget& c0a_default = line_of(B_default, "E_C0A");
  const auto d =
      std::find_if(c0a_default.type_b.begin(), c0a_default.type_b.end(),
                   [](const BudgetLine& b) { return b.effect == "linear_squareness_XY"; });
  REQUIRE(d != c0a_default.type_b.end());
  CHECK(d->basis == "default plausible size");
  CHECK(d->bias_at_size == Approx(shift).epsilon(0.03));
  CHECK(std::find(c0a_default.dominant.begin(), c0a_default.dominant.end(),
                  "linear_squareness_XY") != c0a_default.dominant.end());
}

TEST_CASE("budget arithmetic: combined, Welch-Satterthwaite, coverage factor, overrides",
          "[budget]") {
  const BallbarSession s = simulate_ballbar(commanded(), machine(), {0.5, 12, true});
  BallbarDiagnosisProblem P(s);
  const Diagnosis D = diagnose(P);
  const UncertaintyBudget B = uncertainty_budget(P, D);
  REQUIRE(B.errors.size() == 8);
  int observable = 0;
  for (const LocationBudget& L : B.errors) {
    if (!L.observable) continue;
    ++observable;
    double uc2 = L.u_a * L.u_a, ws = std::pow(L.u_a, 4) / L.dof_a;
    for (const BudgetLine& b : L.type_b) {
      uc2 += b.u * b.u;
      if (std::isfinite(b.dof)) ws += std::pow(b.u, 4) / b.dof;
    }
    CHECK(L.u_c == Approx(std::sqrt(uc2)).epsilon(1e-12));
    CHECK(L.nu_eff == Approx(std::pow(L.u_c, 4) / ws).epsilon(1e-9));
    CHECK(L.k == Approx(stats::t_coverage(0.95, L.nu_eff)).epsilon(1e-12));
    CHECK(L.expanded == Approx(L.k * L.u_c).epsilon(1e-12));
    CHECK(L.k >= 1.95);
    for (std::size_t i = 1; i < L.type_b.size(); ++i) CHECK(L.type_b[i - 1].u >= L.type_b[i].u);
  }
  CHECK(observable >= 6);
  // Doubling one effect's size doubles its line.
  PlausibleSizes big;
  big.overrides["linear_squareness_XY"] = 40e-6;
  const UncertaintyBudget B2 = uncertainty_budget(P, D, big);
  for (std::size_t i = 0; i < 8; ++i) {
    if (!B.errors[i].observable) continue;
    for (const BudgetLine& a : B.errors[i].type_b)
      for (const BudgetLine& b : B2.errors[i].type_b)
        if (a.effect == "linear_squareness_XY" && b.effect == a.effect &&
            a.basis == "default plausible size")
          CHECK(b.u == Approx(2 * a.u).epsilon(1e-9));
  }
  PlausibleSizes bad;
  bad.overrides["no_such_effect"] = 1.0;
  CHECK_THROWS_AS(uncertainty_budget(P, D, bad), InvalidArgument);
  PlausibleSizes negative;
  negative.overrides["linear_squareness_XY"] = -1.0;
  CHECK_THROWS_WITH(uncertainty_budget(P, D, negative), Catch::Contains("linear_squareness_XY.s"));
  CHECK_THROWS_WITH(uncertainty_budget(P, D, {}, 1.5), Catch::Contains("coverage is 1.5"));
}

TEST_CASE("a budget on a reduced design: expanded uncertainties within 1 % of every row's",
          "[budget]") {
  // The independent simulator's session (shared data), its left-out effects evaluated on every
  // third row and both sides of each test's and reversal's break, interpolated in between.
  const BallbarDiagnosisProblem P(commanded());
  const Diagnosis D = diagnose(P);
  const UncertaintyBudget every = uncertainty_budget(P, D, {}, 0.95, 4, 0);
  const UncertaintyBudget reduced = uncertainty_budget(P, D, {}, 0.95, 4, 900);
  REQUIRE(every.errors.size() == reduced.errors.size());
  int compared = 0;
  for (std::size_t i = 0; i < every.errors.size(); ++i) {
    const LocationBudget &e = every.errors[i], &r = reduced.errors[i];
    REQUIRE(e.observable == r.observable);
    if (!e.observable) continue;
    ++compared;
    CHECK(r.u_a == e.u_a);  // type A from every row
    CHECK(std::abs(r.expanded - e.expanded) <= 0.01 * e.expanded);
    CHECK(r.type_b.size() == e.type_b.size());
  }
  CHECK(compared >= 6);
}
