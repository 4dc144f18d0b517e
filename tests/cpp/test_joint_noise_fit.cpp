// SPDX-License-Identifier: BSD-3-Clause
// Joint fits (ballbar and R-test) on correlated noise: the noise model estimated from the
// residuals, the GLS refit, and 1-sigma figures that hold (issue 11 item 1).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "../support/synthetic_sessions.hpp"
#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/monte_carlo.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {

const BallbarSession& commanded() { return synthetic::table2_commanded(); }
BallbarMachineModel random_machine(std::mt19937& rng) {
  return synthetic::random_ballbar_machine(commanded(), rng);
}
// AR(1) noise per test (0.5 um marginal), as the sessions.
BallbarSession ar_ballbar(const BallbarMachineModel& truth, double rho, std::uint64_t seed) {
  return synthetic::noisy_ballbar(commanded(), truth, rho, 0.5, seed);
}

// RMS over sessions and location errors of (estimate - truth) / reported sigma.
template <typename Id, typename Truth>
void accumulate_z(const Id& id, const Truth& truth_errors, MachineType machine, double* sum,
                  int* n) {
  const auto& names = location_error_names(machine);
  for (int j = 0; j < 8; ++j) {
    const ParameterEstimate& p = id.parameter(names[static_cast<std::size_t>(j)]);
    if (!p.observable) continue;
    const double z = (p.value - truth_errors.v[j]) / p.std;
    *sum += z * z;
    ++*n;
  }
}

}  // namespace

TEST_CASE("ballbar joint fit on AR(0.95) noise: white sigmas ~6x too small, GLS ones right",
          "[ballbar][noise]") {
  std::mt19937 rng(11);
  double s_white = 0, s_auto = 0;
  int n_white = 0, n_auto = 0;
  for (int k = 0; k < 6; ++k) {
    const BallbarMachineModel truth = random_machine(rng);
    const BallbarSession s = ar_ballbar(truth, 0.95, 100 + k);
    JointFitOptions white, automatic;
    white.noise.noise = NoiseHandling::white;
    automatic.noise.noise = NoiseHandling::automatic;
    const BallbarIdentification w = identify_joint(s, white);
    const BallbarIdentification a = identify_joint(s, automatic);
    // The white fit still estimates (and reports) the noise model, but does not use it.
    CHECK_FALSE(w.noise_refit);
    CHECK(w.noise.max_order >= 1);
    REQUIRE(a.noise_refit);
    // AR(1) with rho 0.95: tau = (1 + rho) / (1 - rho) = 39 samples; estimated from ~2 x 1800
    // correlated readings per test, within a factor 2 (the largest over the streams is reported).
    CHECK(a.noise.correlation_samples > 39.0 / 2.0);
    CHECK(a.noise.correlation_samples < 39.0 * 2.0);
    CHECK(a.noise.sigma_um == Approx(0.5).epsilon(0.3));
    CHECK(a.noise.effective_samples < 0.1 * static_cast<double>(a.n_samples));
    accumulate_z(w, truth.errors, MachineType::AC_trt, &s_white, &n_white);
    accumulate_z(a, truth.errors, MachineType::AC_trt, &s_auto, &n_auto);
  }
  const double rms_white = std::sqrt(s_white / n_white), rms_auto = std::sqrt(s_auto / n_auto);
  INFO("RMS z: white " << rms_white << ", noise model " << rms_auto << " over " << n_auto);
  CHECK(rms_white > 3.0);  // the issue measured 6.5 over 40 estimates
  // 48 z-scores: the RMS of standard normals is 1 +- 0.1; allow for their correlation.
  CHECK(rms_auto > 0.6);
  CHECK(rms_auto < 1.5);
}

TEST_CASE("ballbar joint fit on white noise: the noise model is white and the fit is done once",
          "[ballbar][noise]") {
  std::mt19937 rng(3);
  const BallbarMachineModel truth = random_machine(rng);
  const BallbarSession s = simulate_ballbar(commanded(), truth, {0.5, 7, false});
  JointFitOptions white, automatic;
  white.noise.noise = NoiseHandling::white;
  automatic.noise.noise = NoiseHandling::automatic;
  const BallbarIdentification a = identify_joint(s, automatic), w = identify_joint(s, white);
  CHECK(a.noise.white());
  CHECK_FALSE(a.noise_refit);
  for (std::size_t j = 0; j < a.parameters.size(); ++j) {
    CHECK(a.parameters[j].value == w.parameters[j].value);
    CHECK(a.parameters[j].std == w.parameters[j].std);
  }
}

TEST_CASE("R-test joint fit with AR(0.95) noise and probe zeros wandering between poses",
          "[rtest][noise]") {
  std::mt19937 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  double s_white = 0, s_auto = 0;
  int n_white = 0, n_auto = 0;
  for (int k = 0; k < 4; ++k) {
    MachineModel truth = MachineModel::nominal(MachineType::BC_trt);
    truth.machine = MachineType::BC_trt;
    for (int i = 0; i < 8; ++i)
      truth.errors.v[i] = location_error_is_angle(i) ? 3e-5 * N(rng) : 0.02 * N(rng);
    RtestSimOptions o;
    o.noise_um = 0.0;
    o.seed = 20 + k;
    RtestSession s = simulate_rtest(truth, o).session;
    std::vector<std::string> g;
    std::vector<double> t;
    for (const RtestSample& x : s.samples)
      for (int a = 0; a < 3; ++a) g.push_back("nest " + x.setup), t.push_back(x.time);
    const Eigen::VectorXd e = noise_gen::ar1(g, t, 0.95, 0.3e-3, 40 + k) +
                              noise_gen::probe_zero_wander(g, t, 0.2e-3, 60 + k);
    for (std::size_t r = 0; r < s.samples.size(); ++r)
      for (int a = 0; a < 3; ++a) (*s.samples[r].d)[a] += e[3 * static_cast<Eigen::Index>(r) + a];
    s.noise_um = 0.3;
    RtestJointOptions white, automatic;
    white.noise.noise = NoiseHandling::white;
    automatic.noise.noise = NoiseHandling::automatic;
    const RtestJointIdentification w = identify_joint(s, white);
    const RtestJointIdentification a = identify_joint(s, automatic);
    REQUIRE(a.noise_refit);
    CHECK(a.noise.correlation_samples > 3.0);
    accumulate_z(w, truth.errors, MachineType::BC_trt, &s_white, &n_white);
    accumulate_z(a, truth.errors, MachineType::BC_trt, &s_auto, &n_auto);
  }
  const double rms_white = std::sqrt(s_white / n_white), rms_auto = std::sqrt(s_auto / n_auto);
  INFO("RMS z: white " << rms_white << ", noise model " << rms_auto << " over " << n_auto);
  CHECK(rms_white > 1.5);  // 1.9 with these seeds
  CHECK(rms_auto > 0.5);
  CHECK(rms_auto < 1.6);
}

TEST_CASE("R-test Monte Carlo re-simulates the fitted noise model (wandering probe zeros)",
          "[rtest][noise]") {
  MachineModel truth = MachineModel::nominal(MachineType::BC_trt);
  truth.machine = MachineType::BC_trt;
  truth.errors.v << 0.01, -0.02, 3e-5, 0.015, -0.01, 0.02, -2e-5, 1e-5;
  RtestSimOptions o;
  o.noise_um = 0.0;
  RtestSession s = simulate_rtest(truth, o).session;
  std::vector<std::string> g;
  std::vector<double> t;
  for (const RtestSample& x : s.samples)
    for (int a = 0; a < 3; ++a) g.push_back("nest " + x.setup), t.push_back(x.time);
  const Eigen::VectorXd e =
      noise_gen::ar1(g, t, 0.9, 0.3e-3, 3) + noise_gen::probe_zero_wander(g, t, 0.1e-3, 4);
  for (std::size_t r = 0; r < s.samples.size(); ++r)
    for (int a = 0; a < 3; ++a) (*s.samples[r].d)[a] += e[3 * static_cast<Eigen::Index>(r) + a];
  s.noise_um = 0.3;
  RtestJointOptions automatic;
  automatic.noise.noise = NoiseHandling::automatic;
  const RtestJointIdentification id = identify_joint(s, automatic);
  REQUIRE(id.noise_refit);
  RtestMonteCarloOptions mo;
  mo.draws = 40;
  const RtestMonteCarlo mc = monte_carlo(s, id, mo);
  CHECK(mc.noise.rfind("the fitted noise model: AR(", 0) == 0);
  int checked = 0;
  for (const MonteCarloParameter& p : mc.parameters) {
    if (p.name.rfind("E_", 0) != 0) continue;
    // Draws from the fitted model see its GLS covariance (times the bias factor, 1 for the
    // REML model); 40 draws: the sample sd within +-35 % at 3 sigma.
    const double r = p.ratio * std::sqrt(id.noise_correction);
    INFO(p.name << " ratio " << p.ratio << ", without the bias factor " << r);
    CHECK(r > 0.65);
    CHECK(r < 1.35);
    ++checked;
  }
  CHECK(checked == 8);
  mo.draws = 1;
  CHECK_THROWS_WITH(monte_carlo(s, id, mo), Catch::Contains("draws"));
}

namespace {
// Spread over sessions of each location error / RMS of its reported sigma (the bench's figure).
struct Ratios {
  std::vector<std::vector<double>> v = std::vector<std::vector<double>>(8),
                                   s = std::vector<std::vector<double>>(8);
  void add(const RtestJointIdentification& id) {
    for (int j = 0; j < 8; ++j) {
      const ParameterEstimate& p =
          id.parameter(location_error_names(MachineType::BC_trt)[static_cast<std::size_t>(j)]);
      REQUIRE(p.observable);
      v[static_cast<std::size_t>(j)].push_back(p.value),
          s[static_cast<std::size_t>(j)].push_back(p.std);
    }
  }
  std::vector<double> ratios() const {
    std::vector<double> out;
    for (std::size_t j = 0; j < 8; ++j) {
      const double n = static_cast<double>(v[j].size());
      double m = 0, var = 0, rep = 0;
      for (double x : v[j]) m += x / n;
      for (double x : v[j]) var += (x - m) * (x - m) / (n - 1);
      for (double x : s[j]) rep += x * x / n;
      out.push_back(std::sqrt(var / rep));
    }
    return out;
  }
};
double rms_log(const std::vector<double>& r) {
  double s = 0;
  for (double x : r) s += std::log(x) * std::log(x);
  return std::sqrt(s / static_cast<double>(r.size()));
}
}  // namespace

TEST_CASE(
    "R-test sigmas hold for every location error under AR(0.9) noise with wandering probe zeros",
    "[rtest][noise]") {
  // Monte Carlo over 50 sessions of one machine (0.3 um AR(0.9) per probe channel, probe zeros
  // stepping 0.1 um per pose, as bench/noise_mc_bench): the spread of each location error over
  // the reported sigma. The old covariance (Burg AR(p) of the residuals, scaled by one bias
  // factor) was 0.49-1.27 here: the walk that the probe zeros and B polynomials take out of the
  // residuals left the B-axis errors' sigmas mis-shaped, which no single factor mends.
  std::mt19937 rng(8);
  std::normal_distribution<double> N(0.0, 1.0);
  MachineModel truth = MachineModel::nominal(MachineType::BC_trt);
  truth.machine = MachineType::BC_trt;
  for (int i = 0; i < 8; ++i)
    truth.errors.v[i] = location_error_is_angle(i) ? 3e-5 * N(rng) : 0.02 * N(rng);
  RtestSimOptions o;
  o.noise_um = 0.0;
  const RtestSession clean = simulate_rtest(truth, o).session;
  std::vector<std::string> g;
  std::vector<double> t;
  for (const RtestSample& x : clean.samples)
    for (int a = 0; a < 3; ++a) g.push_back("nest " + x.setup), t.push_back(x.time);
  RtestJointOptions now, old;
  now.noise.noise = old.noise.noise = NoiseHandling::automatic;
  old.noise.noise_options.reml_random_walk = false;
  Ratios r_now, r_old;
  for (int k = 0; k < 50; ++k) {
    RtestSession s = clean;
    const Eigen::VectorXd e =
        noise_gen::ar1(g, t, 0.9, 0.3e-3, 7000 + static_cast<std::uint64_t>(k)) +
        noise_gen::probe_zero_wander(g, t, 0.1e-3, 8000 + static_cast<std::uint64_t>(k));
    for (std::size_t r = 0; r < s.samples.size(); ++r)
      for (int a = 0; a < 3; ++a) (*s.samples[r].d)[a] += e[3 * static_cast<Eigen::Index>(r) + a];
    s.noise_um = 0.3;
    const RtestJointIdentification a = identify_joint(s, now);
    REQUIRE(a.noise_refit);
    CHECK(a.noise.random_walk_step_um >= 0.0);
    r_now.add(a);
    r_old.add(identify_joint(s, old));
  }
  const std::vector<double> rn = r_now.ratios(), ro = r_old.ratios();
  // 50 draws: each ratio's sampling error is ~10 % (1 sigma); the band allows 3 sigma around
  // the 0.7-1.4, and the RMS of log ratios over the 8 errors (a shape figure, ~0.1 from
  // sampling alone) must stay under 0.25.
  for (int j = 0; j < 8; ++j) {
    const std::size_t u = static_cast<std::size_t>(j);
    INFO(location_error_names(MachineType::BC_trt)[u] << ": now " << rn[u] << ", old " << ro[u]);
    CHECK(rn[u] > 0.6);
    CHECK(rn[u] < 1.6);
  }
  INFO("RMS log ratio: now " << rms_log(rn) << ", old " << rms_log(ro));
  CHECK(rms_log(rn) < 0.25);
  // The test can fail: the old covariance fails it on the same sessions.
  CHECK(rms_log(ro) > 0.25);
}
