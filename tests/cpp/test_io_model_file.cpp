// SPDX-License-Identifier: BSD-3-Clause
// Tests of rotacal-model/1 files (io/model_file.hpp): round trip, strict JSON, versions,
// units and limits, and the files the Python writer made before the C++ one existed.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "rotacal/ballbar/model_document.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/model_file.hpp"

using namespace rotacal;
using json = nlohmann::ordered_json;

namespace {

BallbarMachineModel sample_model() {
  BallbarMachineModel m;
  m.machine = MachineType::AC_trt;
  // Flynn et al. Table 2 magnitudes (mm, rad), not round numbers, so a digit lost shows.
  m.errors.v << 0.0712345678901, -0.0231, 1.234e-4, -5.6789e-5, 0.0133910001, 0.0125, 2.2e-5,
      -3.3e-5;
  m.pivot = Eigen::Vector3d(120.000123, -0.5, 60.25);
  m.effects.effects = {Effect::parse("gravity_sag_A")};
  m.effect_params = {0.004};
  return m;
}

std::string tmp_path(const std::string& name) {
  return "/tmp/rotacal-model-test-" + std::to_string(::getpid()) + "-" + name;
}

}  // namespace

TEST_CASE("a ballbar model survives write and read bit for bit") {
  const BallbarMachineModel m = sample_model();
  const std::string path = tmp_path("m.json");
  write_model(ballbar_model_document(m), path);
  const ModelFile f = read_model(path);
  ::unlink(path.c_str());
  CHECK(f.kind == "ballbar");
  CHECK(f.machine == MachineType::AC_trt);
  for (int k = 0; k < 8; ++k) CHECK(f.location_errors.v[k] == m.errors.v[k]);
  CHECK(*f.pivot == m.pivot);
  const BallbarMachineModel back = ballbar_machine_model(f);
  REQUIRE(back.effects.effects.size() == 1);
  CHECK(back.effects.effects[0] == m.effects.effects[0]);
  CHECK(back.effect_params == m.effect_params);
}

TEST_CASE("a non-finite number is written as null with its reason, never NaN or Infinity") {
  json doc = ballbar_model_document(sample_model());
  doc["location_errors"]["E_Y0A"]["std"] = std::numeric_limits<double>::infinity();
  doc["fit"] = {{"chi2", std::nan("")}};
  const std::string text = format_model(doc);
  CHECK(text.find(": Infinity") == std::string::npos);
  CHECK(text.find(": NaN") == std::string::npos);
  const ModelFile f = parse_model(text, "m.json");
  CHECK(f.document["location_errors"]["E_Y0A"]["std"].is_null());
  CHECK(f.document["fit"]["chi2"].is_null());
  CHECK_THAT(f.document["null_reasons"]["/location_errors/E_Y0A/std"].get<std::string>(),
             Catch::StartsWith("+Infinity"));
  CHECK_THAT(f.document["null_reasons"]["/fit/chi2"].get<std::string>(), Catch::StartsWith("NaN"));
}

TEST_CASE("an unobservable location error (null) is nominal and flagged") {
  json doc = ballbar_model_document(sample_model());
  doc["location_errors"]["E_C0A"] = {
      {"value", nullptr}, {"std", nullptr}, {"unit", "rad"}, {"observable", false}};
  const ModelFile f = model_from_json(doc, "m.json");
  CHECK(f.location_errors.v[3] == 0.0);
  CHECK_FALSE(f.observable[3]);
  CHECK(f.observable[0]);
}

TEST_CASE("versions: a newer major version is refused by name, a minor one is read") {
  json doc = ballbar_model_document(sample_model());
  doc["format"] = "rotacal-model/2";
  CHECK_THROWS_WITH(model_from_json(doc, "new.json"), Catch::Contains("new.json") &&
                                                          Catch::Contains("rotacal-model/2") &&
                                                          Catch::Contains("newer rotacal"));
  doc["format"] = "rotacal-model/1.4";
  doc["added_in_1_4"] = {1, 2, 3};
  const ModelFile f = model_from_json(doc, "minor.json");
  CHECK(f.format_minor == 4);
  CHECK(f.document["added_in_1_4"].size() == 3);  // kept for a round trip
  doc["format"] = "rotacal-ballbar/1";
  CHECK_THROWS_WITH(model_from_json(doc, "x.json"), Catch::Contains("not a rotacal-model file"));
  doc["format"] = "rotacal-model/x";
  CHECK_THROWS_AS(model_from_json(doc, "x.json"), InvalidArgument);
}

TEST_CASE("content errors name the file and the member") {
  const json good = ballbar_model_document(sample_model());
  auto refused = [&](auto change, const std::string& words) {
    json d = good;
    change(d);
    CHECK_THROWS_WITH(model_from_json(d, "bad.json"),
                      Catch::Contains("bad.json") && Catch::Contains(words));
  };
  refused([](json& d) { d["location_errors"]["E_Y0C"]["unit"] = "um"; },
          "location_errors.E_Y0C.unit");
  refused([](json& d) { d["location_errors"]["E_B0A"]["value"] = 1e300; },
          "which no machine tool has");
  refused([](json& d) { d["location_errors"]["E_B0A"]["value"] = "x"; },
          "must be a number or null");
  refused([](json& d) { d["location_errors"].erase("E_Y0A"); }, "location_errors lacks E_Y0A");
  refused([](json& d) { d["location_errors"]["E_X0B"] = {{"value", 0.0}, {"unit", "mm"}}; },
          "not a location error");
  refused([](json& d) { d["machine"] = "XY-trt"; }, "machine");
  refused([](json& d) { d["kind"] = "laser"; }, "kind");
  refused([](json& d) { d["pivot"].erase("z"); }, "pivot.z");
  refused([](json& d) { d["pivot"]["x"]["value"] = 1e160; }, "pivot.x.value");
  refused([](json& d) { d["effects"][0]["id"] = "gravity_sag_B"; }, "does not exist on a AC-trt");
  refused([](json& d) { d["effects"][0]["params"] = json::object(); }, "effects[0].params.s");
  refused([](json& d) { d["location_errors"]["E_Y0A"]["std"] = -1.0; }, "E_Y0A.std");
  refused([](json& d) { d = json::array(); }, "JSON object");
  // The writer refuses what the reader would, so no unreadable file is ever written.
  json bad = good;
  bad["location_errors"]["E_Y0C"]["unit"] = "um";
  CHECK_THROWS_AS(format_model(bad, "out.json"), InvalidArgument);
}

TEST_CASE("syntax errors, NaN tokens and unreadable paths are refused with file, line, column") {
  try {
    parse_model("{\n  \"format\": \"rotacal-model/1\",\n  \"x\": NaN\n}\n", "m.json");
    FAIL("NaN accepted");
  } catch (const ParseError& e) {
    CHECK(e.file() == "m.json");
    CHECK(e.line() == 3);
    CHECK(e.column() >= 8);
  }
  CHECK_THROWS_AS(parse_model("{\"a\": 1,}", "m.json"), ParseError);
  // A number beyond double (nlohmann's out_of_range, not a parse_error: found by the fuzzer).
  CHECK_THROWS_AS(parse_model("{\"format\": -4.8984835417456983e37252275}", "m.json"), ParseError);
  CHECK_THROWS_WITH(read_model("/tmp"), Catch::Contains("directory"));
  CHECK_THROWS_AS(read_model("/tmp"), IoError);
  CHECK_THROWS_AS(read_model("/nonexistent/m.json"), IoError);
}

TEST_CASE("a file as the Python writer made it before the C++ one existed is read") {
  // Verbatim layout of python/rotacal/models.py (json.dumps(model, indent=2)) at 6af68ce:
  // an unobservable error with "observable": false, a cause string, extra fit members.
  const std::string text = R"({
  "format": "rotacal-model/1",
  "kind": "ballbar",
  "machine": "BC-trt",
  "location_errors": {
    "E_X0B": {"value": 0.0213, "std": 0.0004, "unit": "mm"},
    "E_Z0B": {"value": -0.0101, "std": 0.0003, "unit": "mm"},
    "E_A0B": {"value": 4.1e-05, "std": 2e-06, "unit": "rad"},
    "E_C0B": {"value": null, "std": null, "unit": "rad", "observable": false},
    "E_X0C": {"value": 0.0051, "std": 0.0002, "unit": "mm"},
    "E_Y0C": {"value": 0.0134, "std": 0.0002, "unit": "mm"},
    "E_A0C": {"value": -1.2e-05, "std": 1e-06, "unit": "rad"},
    "E_B0C": {"value": 3e-06, "std": 1e-06, "unit": "rad"}
  },
  "pivot": {"x": {"value": 0.01, "std": 0.001, "unit": "mm"},
            "y": {"value": 120.002, "std": 0.001, "unit": "mm"},
            "z": {"value": 59.998, "std": 0.001, "unit": "mm"}},
  "effects": [{"id": "ballbar_length_offset", "cause": "the calibrated ballbar length L0 is wrong",
               "params": {"dL": {"value": 0.0021, "std": 0.0001, "unit": "mm"}}}]
})";
  const ModelFile f = parse_model(text, "old.json");
  CHECK(f.machine == MachineType::BC_trt);
  CHECK(f.location_errors.v[0] == 0.0213);
  CHECK_FALSE(f.observable[3]);
  CHECK(f.pivot->y() == 120.002);
  CHECK(f.effect_params == std::vector<double>{0.0021});
}

namespace {

// An R-test joint model's content on a machine, values of the size a fit gives (mm, rad), not
// round numbers; the map coefficients named as the format names them (d* translations, others
// rotations); one parameter unobservable under its convention.
RtestJointModelContent sample_rtest_content(MachineType machine) {
  RtestJointModelContent c;
  c.machine = machine;
  c.b_degree = 2;
  c.c_harmonics = 1;
  c.c_b_degree = 0;
  c.gamma_cb = false;
  const auto maps = rtest_map_names(machine);
  std::vector<std::string> names(location_error_names(machine).begin(),
                                 location_error_names(machine).end());
  if (machine.has_head()) names.push_back("tool_offset_Z");
  for (const std::string& n :
       {"dz_" + maps[0] + ".b2", "alpha_" + maps[0] + ".b1", "dx_" + maps[1] + ".cos1.b0"})
    names.push_back(n);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const bool angle = i < 8 ? location_error_is_angle(static_cast<int>(i))
                             : names[i] != "tool_offset_Z" && names[i].rfind("d", 0) != 0;
    c.parameters.push_back({names[i],
                            (i % 2 ? -1.0 : 1.0) * (angle ? 3.1e-5 : 0.0123) * (1.0 + 0.137 * i),
                            angle ? 1.7e-6 : 4.3e-4, angle ? "rad" : "mm", true});
  }
  c.parameters[3].observable = false;  // kept at its convention value, written without a std
  const auto n = static_cast<Eigen::Index>(names.size());
  c.covariance = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    c.covariance(i, i) = std::pow(c.parameters[static_cast<std::size_t>(i)].std, 2);
  c.covariance(0, 1) = c.covariance(1, 0) = -1.234567e-8;
  c.nests = {{"1", Eigen::Vector3d(100.125, 0.0, 50.0)},
             {"2", Eigen::Vector3d(-0.3, 99.875, 120.0)}};
  for (const char* setup : {"1", "2"}) {
    std::array<ParameterEstimate, 3> z;
    for (int a = 0; a < 3; ++a)
      z[static_cast<std::size_t>(a)] = {std::string("zero.") + setup + "." + "xyz"[a],
                                        0.00213 * (a + 1), 1.1e-4, "mm", true};
    c.probe_zeros[setup] = z;
  }
  c.residual_rms_um = 0.8123;
  c.sigma_um = 0.79;
  c.n_samples = 432;
  c.converged = true;
  c.unobservable = {"a combination in words"};
  c.notes = {"a note"};
  return c;
}

}  // namespace

TEST_CASE("an R-test joint model is written in C++ and reads back member by member") {
  for (MachineType machine :
       {MachineType::BC_trt, MachineType::AC_trt, parse_machine_type("B-head-C-table")}) {
    CAPTURE(to_string(machine));
    const RtestJointModelContent c = sample_rtest_content(machine);
    const std::string path = tmp_path("rtest.json");
    write_model(rtest_joint_model_document(c), path);
    const ModelFile f = read_model(path);  // the reader's full check of kind rtest-joint
    ::unlink(path.c_str());
    CHECK(f.kind == "rtest-joint");
    CHECK(f.machine == machine);
    const json& d = f.document;
    CHECK(d["basis"]["b_degree"] == 2);
    CHECK(d["basis"]["c_harmonics"] == 1);
    CHECK(d["basis"]["c_b_degree"] == 0);
    CHECK(d["basis"]["gamma_cb"] == false);
    const auto maps = rtest_map_names(machine);
    CHECK(d["basis"]["maps"] == json({maps[0], maps[1]}));
    CHECK(d["basis"]["definition"].get<std::string>().find("Oyama & Ibaraki Eq. 1") !=
          std::string::npos);
    // Every parameter where the format puts it, its value bit for bit.
    const std::size_t n_head = machine.has_head() ? 1 : 0;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < c.parameters.size(); ++i) {
      const ParameterEstimate& p = c.parameters[i];
      names.push_back(p.name);
      const json& e = i < 8            ? d["location_errors"][p.name]
                      : i < 8 + n_head ? d[p.name]
                                       : d["map_coefficients"][p.name];
      CAPTURE(p.name);
      CHECK(e["value"].get<double>() == p.value);
      CHECK(e["unit"] == p.unit);
      if (p.observable) {
        CHECK(e["std"].get<double>() == p.std);
        CHECK_FALSE(e.contains("observable"));
      } else {
        CHECK(e["std"].is_null());
        CHECK(e["observable"] == false);
      }
    }
    CHECK(d["map_coefficients"].size() == 3);
    CHECK(machine.has_head() == d.contains("tool_offset_Z"));
    CHECK(d["covariance"]["parameters"] == json(names));
    for (std::size_t i = 0; i < names.size(); ++i)
      for (std::size_t j = 0; j < names.size(); ++j)
        CHECK(d["covariance"]["matrix"][i][j].get<double>() ==
              c.covariance(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)));
    CHECK(d["nests"]["2"] == json({-0.3, 99.875, 120.0}));
    CHECK(d["probe_zeros"]["2"]["z"]["value"].get<double>() == 0.00213 * 3);
    CHECK(d["fit"]["n_samples"] == 432);
    CHECK(d["fit"]["converged"] == true);
    CHECK(d["fit"]["residual_rms_um"].get<double>() == 0.8123);
    CHECK(d["fit"]["unobservable"] == json({"a combination in words"}));
    // Read and written again: the same text (nothing lost or reordered on the way).
    CHECK(format_model(d, "again") == format_model(rtest_joint_model_document(c), "first"));
  }
}

TEST_CASE("the R-test joint writer refuses content that does not fit the machine") {
  RtestJointModelContent c = sample_rtest_content(MachineType::BC_trt);
  c.covariance = Eigen::MatrixXd::Zero(2, 2);
  CHECK_THROWS_WITH(rtest_joint_model_document(c), Catch::Contains("covariance is not 11 x 11"));
  c.parameters.resize(5);
  CHECK_THROWS_WITH(rtest_joint_model_document(c),
                    Catch::Contains("5 parameters, fewer than the 8"));
}
