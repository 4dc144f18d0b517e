// SPDX-License-Identifier: BSD-3-Clause
// Tests of io/fitted_model.hpp, probe/model_document.hpp and multi/model_document.hpp: the
// model files of a touch-probe identification ("probe") and of one identification from several
// sessions ("multi") read back exactly what was written, a malformed member is refused naming
// it, and the controller export reads the identified errors and their covariance from them.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/io/controller_export.hpp"
#include "rotacal/io/probe_file.hpp"
#include "rotacal/multi/model_document.hpp"
#include "rotacal/probe/model_document.hpp"

using namespace rotacal;
using json = nlohmann::ordered_json;

namespace {

const std::string kData = std::string(ROTACAL_SHARED_DIR) + "/data/";

// NaN equals NaN: a covariance entry written null reads back NaN.
bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

void check_same(const ParameterEstimate& a, const ParameterEstimate& b) {
  INFO(a.name);
  CHECK(a.name == b.name);
  CHECK(a.unit == b.unit);
  CHECK(a.observable == b.observable);
  if (!b.observable) return;  // written null: no value to compare
  CHECK(a.value == b.value);
  CHECK(same(a.std, b.std));
}

void check_same(const std::vector<ParameterEstimate>& a, const std::vector<ParameterEstimate>& b) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) check_same(a[i], b[i]);
}

void check_same(const NoiseModel& a, const NoiseModel& b) {
  CHECK(a.n == b.n);
  CHECK(a.sigma_um == b.sigma_um);
  CHECK(a.innovation_sigma_um == b.innovation_sigma_um);
  CHECK(a.max_order == b.max_order);
  CHECK(a.correlation_samples == b.correlation_samples);
  CHECK(a.effective_samples == b.effective_samples);
  REQUIRE(a.streams.size() == b.streams.size());
  for (std::size_t i = 0; i < a.streams.size(); ++i) {
    CHECK(a.streams[i].group == b.streams[i].group);
    CHECK(a.streams[i].ar == b.streams[i].ar);
    CHECK(a.streams[i].innovation_sigma_um == b.streams[i].innovation_sigma_um);
    CHECK(a.streams[i].sample_interval_s == b.streams[i].sample_interval_s);
  }
}

// The content as written, the content as read back from the file's text.
void check_round_trip(const FittedModelContent& c) {
  const std::string text = format_model(fitted_model_document(c), "m.json");
  const FittedModelContent r = fitted_model_content(parse_model(text, "m.json"), "m.json");
  CHECK(r.kind == c.kind);
  CHECK(r.machine == c.machine);
  check_same(r.location_errors, c.location_errors);
  check_same(r.effect_parameters, c.effect_parameters);
  REQUIRE(r.effects.effects.size() == c.effects.effects.size());
  for (std::size_t i = 0; i < c.effects.effects.size(); ++i)
    CHECK(r.effects.effects[i].id() == c.effects.effects[i].id());
  CHECK(r.covariance_parameters == c.covariance_parameters);
  REQUIRE(r.covariance.rows() == c.covariance.rows());
  for (Eigen::Index i = 0; i < c.covariance.rows(); ++i)
    for (Eigen::Index j = 0; j < c.covariance.cols(); ++j) {
      INFO(c.covariance_parameters[static_cast<std::size_t>(i)]
           << ", " << c.covariance_parameters[static_cast<std::size_t>(j)]);
      // An undetermined parameter's row is written null.
      const bool known =
          r.covariance(i, i) == r.covariance(i, i) && r.covariance(j, j) == r.covariance(j, j);
      if (known) CHECK(same(r.covariance(i, j), c.covariance(i, j)));
    }
  REQUIRE(r.sessions.size() == c.sessions.size());
  for (std::size_t k = 0; k < c.sessions.size(); ++k) {
    CHECK(r.sessions[k].name == c.sessions[k].name);
    CHECK(r.sessions[k].instrument == c.sessions[k].instrument);
    check_same(r.sessions[k].nuisances, c.sessions[k].nuisances);
    check_same(r.sessions[k].alone, c.sessions[k].alone);
    check_same(r.sessions[k].noise, c.sessions[k].noise);
    CHECK(r.sessions[k].noise_refit == c.sessions[k].noise_refit);
    CHECK(r.sessions[k].noise_correction == c.sessions[k].noise_correction);
    CHECK(r.sessions[k].residual_rms_um == c.sessions[k].residual_rms_um);
    CHECK(r.sessions[k].n_residuals == c.sessions[k].n_residuals);
  }
  REQUIRE(r.disagreements.size() == c.disagreements.size());
  for (std::size_t k = 0; k < c.disagreements.size(); ++k) {
    CHECK(r.disagreements[k].parameter == c.disagreements[k].parameter);
    CHECK(r.disagreements[k].z == c.disagreements[k].z);
  }
  CHECK(r.converged == c.converged);
  CHECK(same(r.chi2_per_dof, c.chi2_per_dof));
  CHECK(r.unobservable == c.unobservable);
  CHECK(r.notes == c.notes);
  // And the text of what was read is the text that was written.
  CHECK(format_model(fitted_model_document(r), "m.json") == text);
}

const ProbeIdentification& probe_fit() {
  static const ProbeIdentification id = [] {
    ProbeFitOptions o;
    o.noise.noise = NoiseHandling::automatic;
    return identify_probe(read_probe(kData + "probe_ac_table2.csv"), o);
  }();
  return id;
}

const MultiIdentification& multi_fit() {
  static const MultiIdentification id = [] {
    MultiFitOptions o;
    o.effects.effects.push_back(Effect::parse("gravity_sag_A"));
    return identify_multi(
        {MultiSessionInput::of("ballbar_ac_table2.csv",
                               read_ballbar(kData + "ballbar_ac_table2.csv")),
         MultiSessionInput::of("probe_ac_table2.csv", read_probe(kData + "probe_ac_table2.csv"))},
        o);
  }();
  return id;
}

// `text` with one member replaced, read back: the InvalidArgument's message.
std::string refusal(const json& doc, const std::string& pointer, const json& value) {
  json d = doc;
  d[json::json_pointer(pointer)] = value;
  try {
    parse_model(d.dump(), "bad.json");
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(read without complaint)";
}

}  // namespace

TEST_CASE("a probe identification's model file reads back what was written", "[model][probe]") {
  const ProbeIdentification& id = probe_fit();
  const FittedModelContent c = probe_model_content(id, "probe_ac_table2.csv");
  REQUIRE(c.sessions.size() == 1);
  CHECK(c.sessions[0].instrument == "probe");
  REQUIRE(c.sessions[0].nuisances.size() == 3);  // the sphere on this table-table machine
  CHECK(c.sessions[0].nuisances[0].name == "sphere.x");
  CHECK(c.sessions[0].nuisances[0].value == id.sphere.x());
  for (const ParameterEstimate& p : c.location_errors) CHECK(p.value == id.parameter(p.name).value);
  check_round_trip(c);
  const json doc = probe_model_document(id, "probe_ac_table2.csv");
  CHECK(doc["kind"] == "probe");
  CHECK(doc["model"] == "baseline");
}

TEST_CASE("a joint identification of several sessions reads back what was written",
          "[model][multi]") {
  const MultiIdentification& id = multi_fit();
  const FittedModelContent c = multi_model_content(id);
  REQUIRE(c.sessions.size() == 2);
  CHECK(c.sessions[0].instrument == "ballbar");
  CHECK(c.sessions[1].instrument == "probe");
  CHECK(c.sessions[0].alone.size() == 9);  // 8 location errors and the shared sag
  REQUIRE(c.effect_parameters.size() == 1);
  CHECK(c.effect_parameters[0].name == "gravity_sag_A");
  check_round_trip(c);
  const json doc = multi_model_document(id);
  CHECK(doc["model"] == "extended");
  CHECK(doc["covariance"]["parameters"][9] == "ballbar_ac_table2.csv:pivot_x");
}

TEST_CASE("the cycles' method has no model file", "[model][probe]") {
  const ProbeIdentification cycles =
      identify_probe_cycles(read_probe(kData + "probe_ac_table2.csv"));
  CHECK_THROWS_WITH(probe_model_content(cycles, "p.csv"),
                    Catch::Contains("no uncertainty or covariance"));
}

TEST_CASE("a malformed probe or multi model is refused naming the member", "[model]") {
  const json probe = probe_model_document(probe_fit(), "p.csv");
  const json multi = multi_model_document(multi_fit());
  CHECK_THAT(refusal(probe, "/model", "extended"), Catch::Contains("bad.json: model:"));
  CHECK_THAT(refusal(multi, "/model", "baseline"), Catch::Contains("bad.json: model:"));
  CHECK_THAT(refusal(probe, "/sessions/0/noise_model/gls_refit", "yes"),
             Catch::Contains("sessions[0].noise_model.gls_refit: must be true or false"));
  CHECK_THAT(refusal(probe, "/sessions/0/noise_model/streams/0/ar", json::array({"x"})),
             Catch::Contains("sessions[0].noise_model.streams[0].ar"));
  CHECK_THAT(refusal(probe, "/sessions/0/instrument", "ballbar"),
             Catch::Contains("sessions[0].instrument"));
  CHECK_THAT(refusal(probe, "/sessions/0/nuisances/sphere.x/unit", "um"),
             Catch::Contains("sessions[0].nuisances.sphere.x"));
  CHECK_THAT(refusal(probe, "/location_errors/E_Y0A/std", -1.0),
             Catch::Contains("location_errors.E_Y0A.std"));
  CHECK_THAT(refusal(probe, "/covariance/parameters/0", "E_Q0A"),
             Catch::Contains("covariance.parameters"));
  CHECK_THAT(refusal(probe, "/covariance/matrix/1/1", "0.1"),
             Catch::Contains("covariance.matrix[1]"));
  CHECK_THAT(refusal(probe, "/fit/notes", 3),
             Catch::Contains("fit.notes: must be a list of strings"));
  CHECK_THAT(refusal(multi, "/sessions/1/name", multi["sessions"][0]["name"]),
             Catch::Contains("named twice"));
  CHECK_THAT(refusal(multi, "/sessions/0/alone/E_Q0A", json{{"value", 0.0}}),
             Catch::Contains("sessions[0].alone.E_Q0A: is not a location error"));
  CHECK_THAT(refusal(multi, "/disagreements/0", json{{"parameter", 1}}),
             Catch::Contains("disagreements[0].parameter"));
  json lone = multi;
  lone["sessions"].erase(1);
  CHECK_THROWS_WITH(parse_model(lone.dump(), "one.json"),
                    Catch::Contains("one.json: sessions: a multi model holds two"));
}

TEST_CASE("the controller export takes the errors and their covariance from a probe or multi model",
          "[model][export]") {
  for (const json& doc :
       {probe_model_document(probe_fit(), "p.csv"), multi_model_document(multi_fit())}) {
    const ModelFile m = parse_model(format_model(doc, "m.json"), "m.json");
    const ExportInput in = export_input(m, "m.json");
    CHECK(in.full_covariance);
    const FittedModelContent c = fitted_model_content(m, "m.json");
    for (int i = 0; i < 8; ++i) {
      CHECK(in.errors.v[i] == c.location_errors[static_cast<std::size_t>(i)].value);
      CHECK(std::sqrt(in.covariance(i, i)) ==
            Approx(c.location_errors[static_cast<std::size_t>(i)].std).epsilon(1e-12));
    }
    const ControllerExport ex = export_kinematics(Controller::siemens, in);
    CHECK(ex.errors.size() == 8);
  }
}
