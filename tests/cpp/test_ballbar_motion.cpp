// SPDX-License-Identifier: BSD-3-Clause
// The rotary axes' motion read from a session's time and angle columns (ballbar/motion.hpp),
// and what the motion effects of the catalogue do with it (kinematics/effects.hpp).
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/ballbar/motion.hpp"
#include "rotacal/kinematics/effects.hpp"

using namespace rotacal;

namespace {

constexpr double kDeg = M_PI / 180.0;

BallbarSample row(const std::string& test, double t, double tilt_deg, double rot_deg) {
  BallbarSample s;
  s.test = test;
  s.time = t;
  s.tilt_deg = tilt_deg;
  s.rot_deg = rot_deg;
  return s;
}

Eigen::Vector3d moved(const std::string& id, std::vector<double> p, RotaryAngles<double> a,
                      const RotaryMotion& motion) {
  EffectModel fx{{Effect::parse(id)}};
  REQUIRE(static_cast<int>(p.size()) == fx.num_params());
  return table_point<double>(MachineType::AC_trt, LocationErrors<double>(), fx, p.data(), a, 0.0,
                             Eigen::Vector3d(120, 0, 60), motion);
}

Eigen::Vector3d at_angle(RotaryAngles<double> a) {
  return table_point<double>(MachineType::AC_trt, LocationErrors<double>(), EffectModel{}, nullptr,
                             a, 0.0, Eigen::Vector3d(120, 0, 60));
}

}  // namespace

TEST_CASE("rates, directions and reversals from the time and angle columns", "[ballbar][motion]") {
  // C up at 10 deg/s, a sphere-like rest, C back down at 20 deg/s, then A alone.
  std::vector<BallbarSample> s;
  for (int i = 0; i < 5; ++i) s.push_back(row("up", 0.1 * i, 0.0, 1.0 * i));
  s.push_back(row("rest", 1.0, 0.0, 4.0));
  for (int i = 0; i < 5; ++i) s.push_back(row("down", 2.0 + 0.1 * i, 0.0, 4.0 - 2.0 * i));
  for (int i = 0; i < 3; ++i) s.push_back(row("tilt", 3.0 + 0.1 * i, 1.0 * i, -4.0));
  const std::vector<RotaryMotion> m = rotary_motion(s);
  REQUIRE(m.size() == s.size());
  for (int i = 0; i < 5; ++i) {
    CHECK(m[i].rate.rot == Approx(10.0 * kDeg));  // one-sided at the ends, central inside
    CHECK(m[i].direction.rot == 1.0);
    CHECK(std::isinf(m[i].since_reversal.rot));
    CHECK(m[i].direction.tilt == 0.0);
  }
  CHECK(m[5].rate.rot == 0.0);       // a single row is at rest ...
  CHECK(m[5].direction.rot == 1.0);  // ... on the side it last moved to
  // Reversed where the line through the row before the first row down (at rest at C 4 deg,
  // 1.0 s) meets the line through that row (C 4 deg at 2.0 s, -20 deg/s): at 2.0 s.
  for (int i = 6; i < 11; ++i) {
    CHECK(m[i].rate.rot == Approx(-20.0 * kDeg));
    CHECK(m[i].direction.rot == -1.0);
    CHECK(m[i].since_reversal.rot == Approx(s[i].time - 2.0));
  }
  CHECK(m[11].rate.rot == 0.0);
  CHECK(m[11].direction.rot == -1.0);
  CHECK(m[11].rate.tilt == Approx(10.0 * kDeg));
  CHECK(std::isinf(m[11].since_reversal.tilt));  // A's first move is no reversal
  CHECK(m[12].since_reversal.rot == Approx(s[12].time - 2.0));

  // Rows across a vertex (a program's cw run from where its ccw run ended, sampled between
  // points): the reversal is placed at the vertex, not at the first row after it.
  std::vector<BallbarSample> v;
  for (int i = 0; i < 5; ++i)
    v.push_back(row("ccw", 0.1 * i, 0.0, 10.0 * i));  // up to 40 deg at 0.4 s
  for (int i = 0; i < 5; ++i)
    v.push_back(row("cw", 0.43 + 0.1 * i, 0.0, 40.0 - 100.0 * (0.03 + 0.1 * i)));
  const std::vector<RotaryMotion> mv = rotary_motion(v);
  CHECK(mv[5].since_reversal.rot == Approx(0.43 - 0.4).margin(1e-9));  // vertex at 0.4 s
}

TEST_CASE("motion effects: backlash, servo lag and reversal spikes shift the actual angle",
          "[effects][motion]") {
  const RotaryAngles<double> a{0.3, 1.1};
  RotaryMotion mv;
  mv.rate.rot = 0.2;
  mv.direction.rot = 1.0;
  mv.since_reversal.rot = 0.03;
  // Backlash b: trails by b/2 in the direction of travel; the other way round after reversing.
  const double b = 4e-5;
  CHECK((moved("backlash_C", {b}, a, mv) - at_angle({0.3, 1.1 - b / 2})).norm() < 1e-12);
  RotaryMotion back = mv;
  back.direction.rot = -1.0;
  back.rate.rot = -0.2;
  CHECK((moved("backlash_C", {b}, a, back) - at_angle({0.3, 1.1 + b / 2})).norm() < 1e-12);
  // Servo lag tau: trails by tau * rate.
  CHECK((moved("servo_lag_C", {2e-3}, a, mv) - at_angle({0.3, 1.1 - 2e-3 * 0.2})).norm() < 1e-12);
  // Reversal spike h, tau_s = 0.05 s e^q: h e^(-dt / tau_s) behind, in the new direction.
  const double h = 3e-5, q = std::log(0.4);  // tau_s = 20 ms
  CHECK(
      (moved("reversal_spike_C", {h, q}, a, mv) - at_angle({0.3, 1.1 - h * std::exp(-0.03 / 0.02)}))
          .norm() < 1e-12);
  // The tilt axis reads the tilt's motion, not C's (RotaryMotion members by axis role).
  CHECK((moved("backlash_A", {b}, a, mv) - at_angle(a)).norm() < 1e-15);
  RotaryMotion tilting;
  tilting.direction.tilt = -1.0;
  tilting.rate.tilt = -0.5;
  CHECK((moved("backlash_A", {b}, a, tilting) - at_angle({0.3 + b / 2, 1.1})).norm() < 1e-12);
  CHECK((moved("servo_lag_A", {2e-3}, a, tilting) - at_angle({0.3 + 2e-3 * 0.5, 1.1})).norm() <
        1e-12);
  CHECK((moved("servo_lag_C", {2e-3}, a, tilting) - at_angle(a)).norm() < 1e-15);
  // At rest with no history (a static pose, an R-test): all zero.
  for (const char* id : {"backlash_C", "servo_lag_C", "reversal_spike_A"})
    CHECK(
        (moved(id,
               std::vector<double>(static_cast<std::size_t>(Effect::parse(id).num_params()), 1e-4),
               a, RotaryMotion{}) -
         at_angle(a))
            .norm() < 1e-15);
  CHECK(Effect::parse("servo_lag_A").depends_on_motion());
  CHECK_FALSE(Effect::parse("rotary_zero_offset_C").depends_on_motion());
}
