// SPDX-License-Identifier: BSD-3-Clause
// Tests of the angle maps (rotacal/io/angle_map.hpp): the terms of each table axis against the
// formulas of ../shared/spec/effects.md written out here, and the worst interpolation error
// against a dense evaluation of the same formulas.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "rotacal/compensation/axis_errors.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/angle_map.hpp"

using namespace rotacal;

namespace {

constexpr double kDeg = M_PI / 180.0;

std::string estimate(double v) { return "{\"value\": " + std::to_string(v) + "}"; }

// An AC-trt ballbar model with effects of both axes (the values of a worm gear and a sagging
// table), location errors zero.
ModelFile model_with_effects() {
  std::string le;
  for (const char* n : {"E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C"})
    le += std::string(le.empty() ? "" : ", ") + "\"" + n + "\": " + estimate(0.0);
  const std::string text =
      "{\"format\": \"rotacal-model/1\", \"kind\": \"ballbar\", \"machine\": \"AC-trt\", "
      "\"location_errors\": {" +
      le + "}, \"pivot\": {\"x\": " + estimate(0) + ", \"y\": " + estimate(0) +
      ", \"z\": " + estimate(100) +
      "}, \"effects\": ["
      "{\"id\": \"rotary_zero_offset_C\", \"params\": {\"eps\": " +
      estimate(2e-5) +
      "}},"
      "{\"id\": \"angular_positioning_C_h1\", \"params\": {\"a\": " +
      estimate(1e-4) + ", \"b\": " + estimate(-5e-5) +
      "}},"
      "{\"id\": \"angular_positioning_C_h3\", \"params\": {\"a\": " +
      estimate(0) + ", \"b\": " + estimate(3e-5) +
      "}},"
      "{\"id\": \"radial_motion_C_h2\", \"params\": {\"a\": " +
      estimate(0.002) + ", \"b\": " + estimate(0) + ", \"c\": " + estimate(0) +
      ", \"d\": " + estimate(0.001) +
      "}},"
      "{\"id\": \"gravity_sag_A\", \"params\": {\"s\": " +
      estimate(0.004) +
      "}},"
      "{\"id\": \"backlash_C\", \"params\": {\"b\": " +
      estimate(1e-5) + "}}]}";
  return parse_model(text, "test-model");
}

// effects.md: actual C = C + eps + a1 cos C + b1 sin C + a3 cos 3C + b3 sin 3C.
double positioning_c(double c) {
  return 2e-5 + 1e-4 * std::cos(c) - 5e-5 * std::sin(c) + 3e-5 * std::sin(3 * c);
}

}  // namespace

TEST_CASE("angle maps of catalogue effects follow effects.md", "[angle_map]") {
  const ModelFile model = model_with_effects();
  const std::vector<AxisErrorFunction> fs = axis_error_functions(model, "test-model");
  REQUIRE(fs.size() == 2);
  const AxisErrorFunction& a = fs[0].axis == 'A' ? fs[0] : fs[1];
  const AxisErrorFunction& c = fs[0].axis == 'C' ? fs[0] : fs[1];
  REQUIRE(c.axis == 'C');
  CHECK(c.names[6] == "positioning_C");
  CHECK(c.sources.size() == 4);  // zero offset, two positioning harmonics, radial motion
  CHECK(c.notes.size() == 1);    // the backlash depends on the motion
  for (int i = 0; i < 72; ++i) {
    const double C = (-180.0 + 5.0 * i + 1.7) * kDeg;
    const AngleMapTerms t = c.evaluate(C);
    CHECK(t[6] == Approx(positioning_c(C)).margin(1e-12));
    CHECK(t[5] == Approx(positioning_c(C)).margin(1e-12));  // C turns about +Z
    // The radial motion (2 um cos 2C, 1 um sin 2C) in C's turning frame: its length in the
    // machine frame is the same whatever frame.
    const double radial = std::hypot(0.002 * std::cos(2 * C), 0.001 * std::sin(2 * C));
    CHECK(std::hypot(t[0], t[1]) == Approx(radial).margin(1e-12));
    CHECK(std::abs(t[2]) < 1e-12);
    const AngleMapTerms s = a.evaluate(C);  // the tilt axis at the same angle
    CHECK(s[2] == Approx(-0.004 * (1 - std::cos(C))).margin(1e-12));
    CHECK(std::abs(s[6]) < 1e-15);
  }
}

TEST_CASE("the worst interpolation error is the model's between the points", "[angle_map]") {
  const ModelFile model = model_with_effects();
  const AxisErrorFunction c = axis_error_functions(model, "test-model")[1];
  REQUIRE(c.axis == 'C');
  const AxisAngleMap map = sample_angle_map(c, -360.0, 360.0, 10.0, 16);
  REQUIRE(map.angle_deg.size() == 73);
  CHECK(map.angle_deg.back() == Approx(360.0));
  // The same maximum from the effects.md formula, 2000 angles per interval.
  double dense = 0.0;
  for (std::size_t i = 0; i + 1 < map.angle_deg.size(); ++i)
    for (int s = 1; s < 2000; ++s) {
      const double u = s / 2000.0, x0 = map.angle_deg[i] * kDeg, x1 = map.angle_deg[i + 1] * kDeg;
      const double lin = positioning_c(x0) + u * (positioning_c(x1) - positioning_c(x0));
      dense = std::max(dense, std::abs(positioning_c(x0 + u * (x1 - x0)) - lin));
    }
  CHECK(map.max_interpolation_error[6] <= dense * (1 + 1e-9));
  CHECK(map.max_interpolation_error[6] >= 0.98 * dense);
  CHECK(map.max_abs[6] > 1e-4);
}

TEST_CASE("angle map grids refuse what is not equally spaced", "[angle_map]") {
  CHECK_THROWS_AS(equally_spaced_deg(0, 360, 7, "--spacing"), InvalidArgument);
  CHECK_THROWS_AS(equally_spaced_deg(10, 0, 5, "--spacing"), InvalidArgument);
  CHECK_THROWS_AS(equally_spaced_deg(0, 360, 0, "--spacing"), InvalidArgument);
  CHECK_THROWS_WITH(equally_spaced_deg(0, 360, 7, "--spacing"), Catch::Contains("--spacing"));
  CHECK(equally_spaced_deg(-5, 5, 2.5, "x").size() == 5);
}
