// SPDX-License-Identifier: BSD-3-Clause
// Identification of touch-probe sessions (probe/identify.hpp, probe/problem.hpp): the joint fit
// finds the independent implementation's errors within 3 sigma, finds simulated errors in
// coloured noise with an effect fitted along, its sigma agrees with the scatter of repeated draws,
// and the cycles' method is exact on noiseless data.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "rotacal/io/probe_file.hpp"
#include "rotacal/probe/identify.hpp"
#include "rotacal/probe/simulate.hpp"
#include "rotacal/probe/touch_noise.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;

double truth_value(const std::string& text, const std::string& key, int index = 0) {
  std::size_t at = text.find("\"" + key + "\"");
  REQUIRE(at != std::string::npos);
  at = text.find_first_of("-0123456789", text.find(':', at));
  for (int k = 0; k < index; ++k) at = text.find_first_of("-0123456789", text.find(',', at));
  return std::stod(text.substr(at));
}

MachineModel plausible_machine(MachineType m) {
  MachineModel t = MachineModel::nominal(m);
  t.errors.v << 0.03, -0.02, 2e-5, -3e-5, 0.01, 0.04, -1e-5, 2e-5;
  return t;
}
}  // namespace

TEST_CASE("the joint fit finds the independent session's errors within 3 sigma",
          "[probe][identify]") {
  const ProbeSession s = read_probe(kShared + "/data/probe_ac_table2.csv");
  std::ifstream in(kShared + "/data/probe_ac_table2.truth.json");
  const std::string truth((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const ProbeIdentification id = identify_probe(s);
  CHECK(id.converged);
  CHECK(id.unobservable.empty());
  CHECK(id.residual_rms_um == Approx(0.5).margin(0.15));
  for (const std::string& name : location_error_names(s.machine)) {
    const ParameterEstimate& p = id.parameter(name);
    INFO(name << " = " << p.value << " +- " << p.std << ", truth " << truth_value(truth, name));
    CHECK(p.observable);
    CHECK(std::abs(p.value - truth_value(truth, name)) <= 3 * p.std);
  }
  const char* axes[3] = {"sphere.x", "sphere.y", "sphere.z"};
  for (int k = 0; k < 3; ++k)
    CHECK(std::abs(id.parameter(axes[k]).value - truth_value(truth, "sphere_actual", k)) <=
          3 * id.parameter(axes[k]).std);
}

TEST_CASE("coloured noise and a stylus offset: every error within 3 sigma on every table machine",
          "[probe][identify]") {
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table"}) {
    MachineModel t = plausible_machine(parse_machine_type(name));
    t.effects = EffectModel{{Effect::parse("stylus_radius_offset")}, std::nullopt};
    t.effect_params = {1.5e-3};
    ProbeSimOptions o;
    o.pattern = default_probe_pattern(t.machine);
    o.sphere_offset = Eigen::Vector3d(0.04, -0.03, 0.02);
    o.noise_um = 0.5;
    o.ar1_rho = 0.8;
    o.seed = 7;
    const ProbeSimulation sim = simulate_probe(t, o);
    ProbeFitOptions fo;
    fo.effects = EffectModel{{Effect::parse("stylus_radius_offset")}, std::nullopt};
    fo.noise.noise = NoiseHandling::automatic;  // AR model and GLS refit
    const ProbeIdentification id = identify_probe(sim.session, fo);
    INFO(name);
    CHECK(id.converged);
    // Each latched coordinate is AR(1) from touch to touch, but a residual sees its touch's
    // direction only: successive residuals correlate by rho n_i . n_i+1 (0.2-0.4 here), which the
    // noise model may or may not call correlated; either way the sigmas must hold.
    CHECK(id.noise.n == sim.session.samples.size());
    for (int k = 0; k < 8; ++k) {
      const ParameterEstimate& p = id.parameters[static_cast<std::size_t>(k)];
      if (!p.observable) continue;  // named in id.unobservable
      INFO(p.name << " = " << p.value << " +- " << p.std << ", truth " << t.errors.v[k]);
      CHECK(std::abs(p.value - t.errors.v[k]) <= 3 * p.std);
    }
    const ParameterEstimate& d = id.parameter("stylus_radius_offset");
    CHECK(std::abs(d.value - 1.5e-3) <= 3 * d.std);
    if (!t.machine.has_head()) CHECK(id.unobservable.empty());
  }
}

TEST_CASE("the joint fit's sigma matches the scatter over draws (white noise)",
          "[probe][identify]") {
  const MachineModel t = plausible_machine(MachineType::AC_trt);
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(t.machine);
  o.noise_um = 0.5;
  const int draws = 60;
  Eigen::VectorXd chi2 = Eigen::VectorXd::Zero(8);
  for (int d = 0; d < draws; ++d) {
    o.seed = 100 + static_cast<std::uint64_t>(d);
    const ProbeIdentification id = identify_probe(simulate_probe(t, o).session);
    for (int k = 0; k < 8; ++k) {
      const ParameterEstimate& p = id.parameters[static_cast<std::size_t>(k)];
      chi2[k] += std::pow((p.value - t.errors.v[k]) / p.std, 2) / draws;
    }
  }
  // Mean of (error / sigma)^2 over 60 draws: 1 +- 0.18 (1 sigma) for a correct sigma.
  for (int k = 0; k < 8; ++k) {
    INFO(location_error_names(t.machine)[static_cast<std::size_t>(k)] << ": " << chi2[k]);
    CHECK(chi2[k] > 0.5);
    CHECK(chi2[k] < 1.7);
  }
}

TEST_CASE("the cycles' method is exact on noiseless data and refuses head machines",
          "[probe][cycles]") {
  for (const char* name : {"AC-trt", "BC-trt"}) {
    const MachineModel t = plausible_machine(parse_machine_type(name));
    ProbeSimOptions o;
    o.pattern = default_probe_pattern(t.machine);
    o.sphere_offset = Eigen::Vector3d(0.04, -0.03, 0.02);
    o.noise_um = 0.0;
    const ProbeSimulation sim = simulate_probe(t, o);
    for (bool known : {true, false}) {
      const ProbeIdentification id = identify_probe_cycles(sim.session, {known});
      INFO(name << (known ? " radius known" : " radius free"));
      CHECK(id.method == "cycles");
      CHECK((id.model.errors.v - t.errors.v).cwiseAbs().maxCoeff() < 1e-9);
      CHECK((id.sphere - sim.sphere_actual).norm() < 1e-8);
      CHECK(id.dispersion_um < 1e-6);
      CHECK(std::isnan(id.parameters[0].std));
    }
  }
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(parse_machine_type("B-head-C-table"));
  const ProbeSession head =
      simulate_probe(MachineModel::nominal(parse_machine_type("B-head-C-table")), o).session;
  CHECK_THROWS_AS(identify_probe_cycles(head), InvalidArgument);
  // Too few poses about one axis alone: named.
  ProbeSimOptions few;
  few.pattern = default_probe_pattern(MachineType::AC_trt);
  few.pattern.poses_deg.resize(13);  // one tilt: A turns alone at 2 poses
  const ProbeSession s = simulate_probe(MachineModel::nominal(MachineType::AC_trt), few).session;
  CHECK_THROWS_WITH(identify_probe_cycles(s), Catch::Contains("axis A"));
}

TEST_CASE("touch noise: the whitener is the inverse Cholesky factor of its covariance",
          "[probe][identify]") {
  // Seven touches, rows out of time order in the fit, one row in no stream; the covariance
  // sigma^2 rho^|i-j| n_i . n_j written here from the model's definition.
  const double rho = 0.6, sigma = 2e-3;
  const std::vector<Eigen::Index> rows = {3, 0, 6, 1, 4, 2, 7};
  std::vector<Eigen::Vector3d> n;
  for (int i = 0; i < 7; ++i)
    n.push_back(Eigen::Vector3d(std::cos(1.3 * i), std::sin(0.7 * i), -1.0 - 0.1 * i).normalized());
  const TouchNoiseWhitener W(rows, n, rho, sigma, 8);
  Eigen::MatrixXd V = Eigen::MatrixXd::Identity(8, 8);  // row 5: left as it is
  for (int a = 0; a < 7; ++a)
    for (int b = 0; b < 7; ++b)
      V(rows[static_cast<std::size_t>(a)], rows[static_cast<std::size_t>(b)]) =
          sigma * sigma * std::pow(rho, std::abs(a - b)) *
          n[static_cast<std::size_t>(a)].dot(n[static_cast<std::size_t>(b)]);
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(8, 8);
  W.apply(M);
  CHECK((M * V * M.transpose() - Eigen::MatrixXd::Identity(8, 8)).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(W.log_det() == Approx(std::log(V.determinant())).epsilon(1e-9));
  CHECK_THROWS_AS(TouchNoiseWhitener(rows, n, 1.0, sigma, 8), InvalidArgument);
}

TEST_CASE("touch noise: sigmas match the scatter when each coordinate is AR(1) touch to touch",
          "[probe][identify]") {
  // Noise made here (not by the simulator): X, Y, Z of the touches each AR(1), rho 0.5, 0.5 um,
  // in time order. One AR stream of the residuals called most of these sessions white, and its
  // sigmas came out 10-18 % small (bench/multi_bench, issue 57): mean (error / sigma)^2 about 1.3.
  const MachineModel t = plausible_machine(MachineType::AC_trt);
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(t.machine);
  o.noise_um = 0.0;
  const ProbeSession clean = simulate_probe(t, o).session;
  ProbeFitOptions fit;
  fit.noise.noise = NoiseHandling::automatic;
  const int draws = 100;
  const double rho = 0.5, sigma = 0.5e-3, innov = sigma * std::sqrt(1.0 - rho * rho);
  std::mt19937_64 rng(4242);
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::VectorXd chi2 = Eigen::VectorXd::Zero(8);
  double rho_mean = 0.0;
  for (int d = 0; d < draws; ++d) {
    ProbeSession s = clean;
    s.noise_um = 0.5;
    Eigen::Vector3d x(sigma * N(rng), sigma * N(rng), sigma * N(rng));
    for (ProbeSample& p : s.samples) {
      p.xyz += x;
      x = rho * x + innov * Eigen::Vector3d(N(rng), N(rng), N(rng));
    }
    const ProbeIdentification id = identify_probe(s, fit);
    rho_mean +=
        (id.noise.streams.empty() || id.noise.streams[0].ar.empty() ? 0.0
                                                                    : id.noise.streams[0].ar[0]) /
        draws;
    for (int k = 0; k < 8; ++k) {
      const ParameterEstimate& p = id.parameters[static_cast<std::size_t>(k)];
      chi2[k] += std::pow((p.value - t.errors.v[k]) / p.std, 2) / draws;
    }
  }
  INFO("mean (error / sigma)^2 per error: " << chi2.transpose() << "; mean rho " << rho_mean);
  // 100 draws: 1 +- 0.14 per error for a correct sigma; the mean of the 8 (correlated) tighter.
  CHECK(chi2.mean() > 0.8);
  CHECK(chi2.mean() < 1.15);
  CHECK(chi2.maxCoeff() < 1.5);
  CHECK(rho_mean == Approx(0.5).margin(0.1));
}
