// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/error_map.hpp: map writers and held-out prediction.
#include <catch2/catch.hpp>
#include <iostream>
#include <nlohmann/json.hpp>

#include "../support/synthetic_sessions.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/rtest/error_map.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
MachineModel truth() {  // rtest_bc_oyama.truth.json + a C-axis face runout (2 lobes)
  MachineModel t = synthetic::oyama_truth();
  t.effects.effects.push_back(Effect::parse("axial_motion_C_h2"));
  t.effect_params.insert(t.effect_params.end(), {0.002, -0.001});
  return t;
}
constexpr double kDeg = M_PI / 180.0;
}  // namespace

TEST_CASE("fit on C = 0, 30, ...; predict held-out C = 15, 45, ... to the noise level") {
  RtestSimOptions fit_o;
  fit_o.seed = 8;
  const RtestSimulation fit = simulate_rtest(truth(), fit_o);
  RtestSimOptions held_o = fit_o;
  held_o.seed = 9;
  held_o.pattern.c_deg.clear();
  for (int j = 0; j < 12; ++j) held_o.pattern.c_deg.push_back(15.0 + 30.0 * j);
  const RtestSimulation held = simulate_rtest(truth(), held_o);

  const RtestJointIdentification joint = identify_joint(fit.session);
  const double rms_joint = prediction_rms_um(
      held.session,
      [&](const Eigen::Vector3d& q, double B, double C) { return joint.model.reading(q, B, C); });
  const RtestPaperIdentification paper = identify_paper(fit.session);
  const double rms_paper = prediction_rms_um(
      held.session,
      [&](const Eigen::Vector3d& q, double B, double C) { return paper.predict_reading(q, B, C); });
  std::cout << "held-out prediction RMS: joint " << rms_joint << " um, paper " << rms_paper
            << " um (noise 0.3 um)\n";
  // The held-out readings carry 0.3 um noise; the joint model adds its own prediction error
  // (~0.3 * sqrt(p/n) ~ 0.1 um): within 20% of the noise.
  CHECK(rms_joint < 0.36);
  CHECK(rms_joint > 0.24);
  // Linear interpolation between 30-deg C positions misses a 2-lobe runout by ~ 1 - cos 30deg.
  CHECK(rms_paper > rms_joint);

  // Prediction uncertainty: the 1-sigma of a predicted reading is below the noise and > 0.
  Eigen::Vector3d sd;
  joint.model.reading(Eigen::Vector3d(100, 0, 60), 45 * kDeg, 15 * kDeg, &sd);
  for (int k = 0; k < 3; ++k) {
    CHECK(sd[k] > 0.0);
    CHECK(sd[k] < 0.3e-3);
  }
  // Table error of a table point with its 1 sigma (finite: every parameter is observable).
  Eigen::Vector3d te_sd;
  const Eigen::Vector3d te =
      joint.model.table_error(Eigen::Vector3d(50, 50, 0), M_PI / 2, 0.0, &te_sd);
  CHECK(te.allFinite());
  CHECK((te_sd.array() > 0.0).all());
}

TEST_CASE("error map writers") {
  RtestSimOptions o;
  const RtestSimulation sim = simulate_rtest(truth(), o);
  const RtestJointIdentification joint = identify_joint(sim.session);
  const RtestErrorMap m = error_map(joint, {-90, 0, 90}, {0, 90});
  REQUIRE(m.entries.size() == 6);
  const std::string csv = error_map_csv(m);
  CHECK(csv.rfind("B,C,dx_BY,", 0) == 0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 7);
  const std::string json = error_map_json(m);
  CHECK(json.find("\"method\": \"joint\"") != std::string::npos);
  CHECK(json.find("\"entries\"") != std::string::npos);
  // At B = -90 the map's dz_BY is the sag (~ -6 um) in both writers' first data row.
  CHECK(m.entries[0].w_BY[2] < -0.005);
  const RtestErrorMap pm = error_map(identify_paper(sim.session));
  CHECK(pm.entries.size() == 84);
  CHECK(error_map_csv(pm).find(",\n") != std::string::npos);  // gamma_CB std: not identified
  // Strict JSON: parsed by nlohmann (no NaN tokens), the null explained, every entry there.
  const nlohmann::json pj = nlohmann::json::parse(error_map_json(pm));
  CHECK(pj["entries"].size() == 84);
  CHECK(pj["entries"][0]["CB_std"][5].is_null());
  CHECK(pj["entries"][0]["CB"][0].get<double>() == pm.entries[0].w_CB[0]);
  CHECK_THAT(pj["null_means"].get<std::string>(), Catch::Contains("not identified"));
  RtestErrorMap quoted = m;
  quoted.notes = {"a \"quoted\" note\twith a tab and \x01 control", "non-ASCII: \xc2\xb5m"};
  const nlohmann::json qj = nlohmann::json::parse(error_map_json(quoted));
  CHECK(qj["notes"][0].get<std::string>() == quoted.notes[0]);
  CHECK(qj["notes"][1].get<std::string>() == quoted.notes[1]);
  CHECK_FALSE(nlohmann::json::parse(error_map_json(m)).contains("null_means"));
  CHECK_THROWS_AS(write_text_file("/nonexistent-dir/x.csv", csv), IoError);
}
