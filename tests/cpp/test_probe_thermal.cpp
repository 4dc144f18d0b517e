// SPDX-License-Identifier: BSD-3-Clause
// The joint fit of a thermal probe session (probe/thermal.hpp) on the independent
// implementation's thermal_probe_ac.csv, judged against its .truth.json.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <sstream>

#include "rotacal/core/json_text.hpp"
#include "rotacal/probe/thermal.hpp"
#include "rotacal/session/thermal_summary.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;

nlohmann::ordered_json truth_of(const std::string& name) {
  std::ifstream in(kShared + "/data/" + name);
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_json(ss.str(), name);
}
}  // namespace

TEST_CASE("thermal_probe_ac.csv: tau and every determinable gain within 3 sigma of the truth",
          "[probe][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_probe_ac.csv");
  const auto& s = std::get<ProbeSession>(t.session);
  const ThermalIdentification id = identify_thermal_probe(s, t.thermal);
  const auto truth = truth_of("thermal_probe_ac.truth.json");
  const auto& lag = truth["thermal"][0];
  REQUIRE(id.converged);
  REQUIRE(id.lags.size() == 1);
  CHECK(id.axis == 'C');
  CHECK(id.tested_speed_rpm == 300.0);
  const double tau = lag["tau_s"].get<double>();
  INFO("tau " << id.lags[0].tau_s << " +- " << id.lags[0].tau_std_s << " truth " << tau);
  CHECK(id.lags[0].tau_observable);
  CHECK(std::abs(id.lags[0].tau_s - tau) <= 3.0 * id.lags[0].tau_std_s);
  int determined = 0;
  for (const ThermalGainEstimate& g : id.lags[0].gains) {
    const double want = lag["gains"][g.name].get<double>();
    INFO(g.name << " " << g.value << " +- " << g.std << " truth " << want << " " << g.reason);
    if (!g.observable) {
      CHECK_FALSE(g.reason.empty());
      continue;
    }
    ++determined;
    CHECK(g.std > 0.0);
    CHECK(std::abs(g.value - want) <= 3.0 * g.std);
  }
  CHECK(determined >= 8);
  // The cold location errors too (the set-up's sphere: truth's sphere_actual).
  for (int k = 0; k < 8; ++k) {
    const ThermalGainEstimate& c = id.cold[static_cast<std::size_t>(k)];
    if (!c.observable) continue;
    const double want = truth["errors"][c.name].get<double>();
    INFO(c.name << " " << c.value << " +- " << c.std << " truth " << want);
    CHECK(std::abs(c.value - want) <= 3.0 * c.std);
  }
  CHECK(id.residual_rms_um < 0.6);  // noise 0.5 um: the model leaves nothing else
}

TEST_CASE("a thermal probe session without duty: gains unobservable, for that reason",
          "[probe][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_probe_ac.csv");
  ThermalTest cold = t.thermal;
  cold.duty.clear();
  const ThermalIdentification id = identify_thermal_probe(std::get<ProbeSession>(t.session), cold);
  CHECK(id.axis == 0);
  for (const ThermalGainEstimate& g : id.lags[0].gains) {
    CHECK_FALSE(g.observable);
    CHECK_THAT(g.reason, Catch::Contains("no heat input"));
  }
  const ThermalSummary s = thermal_summary(id);  // nothing to test: no drift found
  CHECK(s.drift_test.gains == 0);
  CHECK_FALSE(s.drift_test.drift_found);
  CHECK(s.no_significant_drift);
}

TEST_CASE("thermal summary of the shared probe session", "[probe][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_probe_ac.csv");
  const ThermalIdentification id =
      identify_thermal_probe(std::get<ProbeSession>(t.session), t.thermal);
  ThermalSummaryOptions o;
  o.tolerance_mm = 0.005;
  o.tolerance_rad = 10e-6;
  const ThermalSummary s = thermal_summary(id, o);
  REQUIRE(s.drifts.size() == 11);
  CHECK(s.tau_s[0] == id.lags[0].tau_s);
  const double tau = s.tau_s[0];
  int never = 0, timed = 0;
  for (std::size_t k = 0; k < s.drifts.size(); ++k) {
    const ThermalDrift& d = s.drifts[k];
    const ThermalGainEstimate& g = id.lags[0].gains[k];
    INFO(d.name << " " << d.steady_change << " +- " << d.steady_std);
    REQUIRE(d.observable);
    CHECK(d.steady_change == Approx(3.0 * g.value));  // 300 rev/min = 3 x 100
    CHECK(d.steady_std == Approx(3.0 * g.std));
    CHECK(d.significant == (std::abs(g.value) > 3.0 * g.std));
    // One lag: the bound is (|Delta| + 1.645 sigma)(1 - exp(-t / tau)), crossing the tolerance
    // at -tau ln(1 - tol / bound) when the bound at steady state exceeds it.
    const double tol = d.unit == "rad" ? 10e-6 : 0.005;
    const double bound = std::abs(d.steady_change) + 1.6448536269514722 * d.steady_std;
    if (bound <= tol) {
      CHECK_FALSE(d.exceeds_after_s);
      ++never;
    } else {
      REQUIRE(d.exceeds_after_s);
      CHECK(*d.exceeds_after_s == Approx(-tau * std::log(1.0 - tol / bound)).epsilon(1e-9));
      ++timed;
    }
  }
  CHECK(never > 0);  // e.g. q_z: 0.47 um at 300 rev/min
  CHECK(timed > 0);  // E_X0C: -23 um at 300 rev/min
  const auto j = to_json(s);
  CHECK(j["drifts"].size() == 11);
  CHECK(j["lags"][0]["tau_s"].get<double>() == tau);
  CHECK_THROWS_AS(thermal_summary(id, ThermalSummaryOptions{-1.0, {}}), InvalidArgument);
  // The joint drift test's W against a direct solve with the raw covariance (it inverts the
  // correlation matrix by its eigen-decomposition).
  Eigen::VectorXd g(11);
  Eigen::MatrixXd c(11, 11);
  for (int a = 0; a < 11; ++a) {
    g(a) = id.lags[0].gains[static_cast<std::size_t>(a)].value;
    for (int b = 0; b < 11; ++b)
      c(a, b) = id.covariance(id.gain_index[0] + a, id.gain_index[0] + b);
  }
  const ThermalDriftTest& dt = s.drift_test;
  CHECK(dt.statistic == Approx(g.dot(c.ldlt().solve(g))).epsilon(1e-6));
  CHECK(dt.gains == 11);
  CHECK(dt.residual_dof == id.n_samples - 23.0);  // 1480 touches, 23 free parameters, white
  CHECK(dt.drift_found);
  CHECK_FALSE(s.no_significant_drift);
  CHECK(j["drift_test"]["drift_found"].get<bool>());
  CHECK_THROWS_AS(thermal_drift_test(id, 1.0), InvalidArgument);
}

TEST_CASE("the per-epoch peer on the shared probe session", "[probe][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_probe_ac.csv");
  const auto& s = std::get<ProbeSession>(t.session);
  const ThermalIdentification joint = identify_thermal_probe(s, t.thermal);
  const ThermalIdentification peer = thermal_peer_probe(s, t.thermal);
  const auto truth = truth_of("thermal_probe_ac.truth.json");
  const auto& lag = truth["thermal"][0];
  REQUIRE(peer.converged);
  REQUIRE(peer.lags.size() == 1);
  CHECK(peer.n_epochs == 37);
  INFO("peer tau " << peer.lags[0].tau_s << " +- " << peer.lags[0].tau_std_s << ", joint "
                   << joint.lags[0].tau_s << " +- " << joint.lags[0].tau_std_s);
  CHECK(std::abs(peer.lags[0].tau_s - lag["tau_s"].get<double>()) <= 3.0 * peer.lags[0].tau_std_s);
  // The joint fit uses every touch through one model: its sigma is not larger than the peer's.
  CHECK(joint.lags[0].tau_std_s <= peer.lags[0].tau_std_s);
  for (std::size_t k = 0; k < peer.lags[0].gains.size(); ++k) {
    const ThermalGainEstimate& g = peer.lags[0].gains[k];
    INFO(g.name << " peer " << g.value << " +- " << g.std << " joint "
                << joint.lags[0].gains[k].value << " +- " << joint.lags[0].gains[k].std);
    if (!g.observable) continue;
    CHECK(std::abs(g.value - lag["gains"][g.name].get<double>()) <= 3.0 * g.std);
  }
}
