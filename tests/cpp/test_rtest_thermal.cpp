// SPDX-License-Identifier: BSD-3-Clause
// The joint fit of a thermal R-test session (rtest/thermal.hpp) on the independent
// implementation's thermal_rtest_bc.csv, judged against its .truth.json.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <sstream>

#include "rotacal/core/json_text.hpp"
#include "rotacal/rtest/thermal.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;
}  // namespace

TEST_CASE("thermal_rtest_bc.csv: tau and every determinable gain within 3 sigma of the truth",
          "[rtest][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_rtest_bc.csv");
  const ThermalIdentification id =
      identify_thermal_rtest(std::get<RtestSession>(t.session), t.thermal);
  std::ifstream in(kShared + "/data/thermal_rtest_bc.truth.json");
  std::stringstream ss;
  ss << in.rdbuf();
  const auto truth = parse_json(ss.str(), "thermal_rtest_bc.truth.json");
  const auto& lag = truth["thermal"][0];
  REQUIRE(id.converged);
  CHECK(id.axis == 'C');
  CHECK(id.tested_speed_rpm == 200.0);
  const double tau = lag["tau_s"].get<double>();
  INFO("tau " << id.lags[0].tau_s << " +- " << id.lags[0].tau_std_s << " truth " << tau);
  REQUIRE(id.lags[0].tau_observable);
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
    CHECK(std::abs(g.value - want) <= 3.0 * g.std);
  }
  CHECK(determined >= 8);
  for (const ThermalGainEstimate& c : id.cold) {
    if (!c.observable) continue;
    const double want = truth["errors"][c.name].get<double>();
    INFO(c.name << " " << c.value << " +- " << c.std << " truth " << want);
    CHECK(std::abs(c.value - want) <= 3.0 * c.std);
  }
}

TEST_CASE("a nest dismounted between epochs: its gains unobservable, for that reason",
          "[rtest][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_rtest_bc.csv");
  RtestSession s = std::get<RtestSession>(t.session);
  const Eigen::Vector3d nest = s.nests.at("1");
  s.nests.clear();
  for (std::size_t i = 0; i < s.samples.size(); ++i) {  // each epoch a set-up of its own
    s.samples[i].setup = std::to_string(t.thermal.epoch[i]);
    s.nests[s.samples[i].setup] = nest;
  }
  const ThermalIdentification id = identify_thermal_rtest(s, t.thermal);
  REQUIRE(id.lags[0].gains.size() == 8 + 3 * 28);
  for (std::size_t k = 0; k < id.lags[0].gains.size(); ++k) {
    const ThermalGainEstimate& g = id.lags[0].gains[k];
    INFO(g.name << " " << g.reason);
    CHECK(g.observable == (k < 8));
    if (k >= 8) CHECK_THAT(g.reason, Catch::Contains("dismounted between epochs"));
  }
  CHECK(id.lags[0].tau_observable);
}
