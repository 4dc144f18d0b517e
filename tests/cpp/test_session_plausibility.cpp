// SPDX-License-Identifier: BSD-3-Clause
// Tests of session/plausibility.hpp: the shared sessions pass; sessions with the careless mistakes
// of issue 17 item 5 are refused with the cause named.
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/session/plausibility.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;
constexpr double kDeg = M_PI / 180.0;

template <typename Session>
std::string refusal(const Session& s, const PlausibilityOptions& o = {}) {
  try {
    check_plausible(s, "s.csv", o);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  FAIL("accepted an implausible session");
  return "";
}
}  // namespace

TEST_CASE("the shared sessions are plausible, with deviations of a real machine") {
  for (const char* name : {"ballbar_ac_table2.csv", "ballbar_ac_random.csv"}) {
    const BallbarSession s = read_ballbar(kShared + "/data/" + name);
    const PlausibilityReport r = check_plausible(s, name);
    CHECK(r.max_deviation_mm < 0.5);  // location errors of tens of um, a pivot set-up error
    CHECK(r.tilt_span_deg > 100.0);
  }
  const RtestSession rt = read_rtest(kShared + "/data/rtest_bc_oyama.csv");
  const PlausibilityReport r = check_plausible(rt, "rtest_bc_oyama.csv");
  CHECK(r.max_deviation_mm < 0.5);
}

TEST_CASE("ballbar: radians, inches, a wrong L0, axes that never move, one wild row") {
  const BallbarSession good = read_ballbar(kShared + "/data/ballbar_ac_table2.csv");

  BallbarSession rad = good;
  for (BallbarSample& b : rad.samples) b.tilt_deg *= kDeg, b.rot_deg *= kDeg;
  CHECK_THAT(refusal(rad), Catch::Contains("angles look like radians") && Catch::Contains("s.csv"));

  BallbarSession inch = good;
  for (BallbarSample& b : inch.samples) b.length /= 25.4;
  CHECK_THAT(refusal(inch), Catch::Contains("lengths look like inches"));

  BallbarSession all_inch = good;
  all_inch.ballbar_length /= 25.4;
  all_inch.pivot /= 25.4;
  for (BallbarSample& b : all_inch.samples) b.length /= 25.4, b.xyz /= 25.4;
  CHECK_THAT(refusal(all_inch), Catch::Contains("inches"));

  BallbarSession l150 = good;
  l150.ballbar_length = 150.0;
  CHECK_THAT(refusal(l150), Catch::Contains("ballbar_length 150 and the commanded positions") ||
                                Catch::Contains("ballbar_length 150 but the data say ~100"));

  BallbarSession l0_only = good;
  l0_only.ballbar_length = 100.0;
  for (BallbarSample& b : l0_only.samples) b.length += 50.0;
  CHECK_THAT(refusal(l0_only), Catch::Contains("measured lengths are ~150"));

  BallbarSession still = good;
  for (BallbarSample& b : still.samples) b.tilt_deg = 0.0, b.rot_deg = 0.0;
  CHECK_THAT(refusal(still), Catch::Contains("all rotary angles equal: the axes never move"));

  BallbarSession wild = good;
  wild.samples[500].length += 3.0;
  const std::string w = refusal(wild);
  CHECK_THAT(w, Catch::Contains("sample 500") && Catch::Contains("max_length_deviation_mm"));
  PlausibilityOptions wide;
  wide.max_length_deviation_mm = 5.0;
  CHECK_NOTHROW(check_plausible(wild, "s.csv", wide));
}

TEST_CASE("R-test: radians, displacements in um, a wrong nest") {
  const RtestSession good = read_rtest(kShared + "/data/rtest_bc_oyama.csv");
  RtestSession rad = good;
  for (RtestSample& r : rad.samples) r.tilt_deg *= kDeg, r.rot_deg *= kDeg;
  CHECK_THAT(refusal(rad), Catch::Contains("angles look like radians"));

  RtestSession um = good;
  for (RtestSample& r : um.samples) *r.d *= 1000.0;
  CHECK_THAT(refusal(um), Catch::Contains("displacements in um"));

  RtestSession nest = good;
  nest.nests.begin()->second.z() += 10.0;
  CHECK_THAT(refusal(nest), Catch::Contains("nest." + good.nests.begin()->first));

  RtestSession inch = good;
  for (RtestSample& r : inch.samples) r.xyz /= 25.4;
  CHECK_THAT(refusal(inch), Catch::Contains("inches"));
}

TEST_CASE("a model of another machine is refused by name") {
  CHECK_THROWS_WITH(check_model_machine(MachineType::AC_trt, MachineType::BC_trt, "m.json"),
                    Catch::Contains("session machine BC-trt, model AC-trt (m.json)"));
  CHECK_NOTHROW(check_model_machine(MachineType::BC_trt, MachineType::BC_trt, "m.json"));
}
