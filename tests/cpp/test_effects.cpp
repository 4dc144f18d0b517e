// SPDX-License-Identifier: BSD-3-Clause
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <random>

#include "rotacal/kinematics/effects.hpp"

using namespace rotacal;
using Catch::Matchers::WithinAbs;

namespace {
Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

Eigen::Vector3d moved(MachineType m, const std::string& id, std::vector<double> p,
                      RotaryAngles<double> a, const Eigen::Vector3d& q, double t = 0.0) {
  EffectModel fx{{Effect::parse(id)}};
  REQUIRE(static_cast<int>(p.size()) == fx.num_params());
  return table_pose<double>(m, LocationErrors<double>(), fx, p.data(), a, t) * q;
}
}  // namespace

TEST_CASE("every catalogue id round-trips and bad ids are refused", "[effects]") {
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    const auto cat = effect_catalogue(m, 4);
    CHECK(cat.size() > 30);
    for (const Effect& f : cat) {
      CHECK(Effect::parse(f.id()) == f);
      CHECK(f.applies_to(m));
      CHECK(static_cast<int>(f.param_names().size()) == f.num_params());
      CHECK(f.param_units().size() == f.param_names().size());
    }
  }
  CHECK(Effect::parse("angular_positioning_C_h3").harmonic == 3);
  CHECK(Effect::parse("linear_squareness_ZX").axis == 'Z');
  CHECK_FALSE(Effect::parse("gravity_sag_A").applies_to(MachineType::BC_trt));
  for (const char* bad : {"", "gravity_sag_C", "radial_motion_C_h1", "coning", "tilt_motion_C",
                          "angular_positioning_Q_h1", "linear_scale_W", "tool_offset_Z_h1",
                          "linear_squareness_XZ", "angular_positioning_C_hx"}) {
    CHECK_THROWS_AS(Effect::parse(bad), InvalidArgument);
  }
  CHECK_THROWS_WITH(Effect::parse("coning_C"), Catch::Contains("coning_C"));
}

TEST_CASE("a session's effect is named after its session and is not the machine's", "[effects]") {
  // diagnose/multi_session.hpp: "probe2:stylus_radius_offset" is session probe2's own.
  const Effect own = Effect::parse("probe2:stylus_radius_offset");
  CHECK(own.session == "probe2");
  CHECK(own.kind == EffectKind::stylus_radius_offset);
  CHECK(own.id() == "probe2:stylus_radius_offset");
  CHECK(Effect::parse(own.id()) == own);
  CHECK_FALSE(own == Effect::parse("stylus_radius_offset"));
  CHECK(Effect::parse("bb:thermal_warmup_Z").num_params() == 2);
  CHECK_THROWS_AS(Effect::parse(":coning_A"), InvalidArgument);
  CHECK_THROWS_WITH(Effect::parse("bb:coning_C"), Catch::Contains("coning_C"));
}

TEST_CASE("angle effects shift the actual angle", "[effects]") {
  const Eigen::Vector3d q(100, 20, 50);
  const auto m = MachineType::AC_trt;
  const double C = 0.7, A = -0.4, eps = 1e-3;
  CHECK((moved(m, "rotary_zero_offset_C", {eps}, {A, C}, q) - Rx(A) * Rz(C + eps) * q).norm() <
        1e-12);
  CHECK((moved(m, "rotary_zero_offset_A", {eps}, {A, C}, q) - Rx(A + eps) * Rz(C) * q).norm() <
        1e-12);
  const double a = 2e-4, b = -1e-4, dC = a * std::cos(2 * C) + b * std::sin(2 * C);
  CHECK((moved(m, "angular_positioning_C_h2", {a, b}, {A, C}, q) - Rx(A) * Rz(C + dC) * q).norm() <
        1e-12);
}

TEST_CASE("error motions act in the axis' turning frame before its rotation", "[effects]") {
  const auto m = MachineType::BC_trt;
  const Eigen::Vector3d q(100, 0, 60);
  const double B = 0.5, C = 1.1, n = 3;
  const double a = 1e-3, b = 2e-3, c = -1e-3, d = 5e-4;
  const double u = a * std::cos(n * C) + b * std::sin(n * C),
               v = c * std::cos(n * C) + d * std::sin(n * C);
  // C turns about Z: the perpendicular pair is (X, Y) of C's turning frame.
  CHECK((moved(m, "radial_motion_C_h3", {a, b, c, d}, {B, C}, q) -
         Ry(B) * Rz(C) * (q + Eigen::Vector3d(u, v, 0)))
            .norm() < 1e-12);
  CHECK((moved(m, "axial_motion_C_h3", {a, b}, {B, C}, q) -
         Ry(B) * Rz(C) * (q + Eigen::Vector3d(0, 0, u)))
            .norm() < 1e-12);
  CHECK((moved(m, "tilt_motion_C_h3", {a, b, c, d}, {B, C}, q) - Ry(B) * Rz(C) * Rx(u) * Ry(v) * q)
            .norm() < 1e-12);
  // B turns about Y: its perpendicular pair is (Z, X), and E_B acts after C has turned.
  const double uB = a * std::cos(2 * B) + b * std::sin(2 * B),
               vB = c * std::cos(2 * B) + d * std::sin(2 * B);
  CHECK((moved(m, "radial_motion_B_h2", {a, b, c, d}, {B, C}, q) -
         Ry(B) * (Rz(C) * q + Eigen::Vector3d(vB, 0, uB)))
            .norm() < 1e-12);
}

TEST_CASE("tilt-axis effects: gravity sag, coning, drift", "[effects]") {
  const Eigen::Vector3d q(100, -20, 60);
  const double B = -1.2, C = 0.3;
  CHECK((moved(MachineType::BC_trt, "gravity_sag_B", {0.006}, {B, C}, q) -
         (Ry(B) * Rz(C) * q - Eigen::Vector3d(0, 0, 0.006 * (1 - std::cos(B)))))
            .norm() < 1e-12);
  CHECK((moved(MachineType::BC_trt, "coning_B", {1.45e-4}, {B, C}, q) -
         Rx(1.45e-4 * B) * Ry(B) * Rz(C) * q)
            .norm() < 1e-12);
  CHECK(
      (moved(MachineType::AC_trt, "coning_A", {1e-4}, {B, C}, q) - Ry(1e-4 * B) * Rx(B) * Rz(C) * q)
          .norm() < 1e-12);
  CHECK((moved(MachineType::AC_trt, "thermal_drift_Y", {1e-5}, {B, C}, q, 100.0) -
         (Rx(B) * Rz(C) * q + Eigen::Vector3d(0, 1e-3, 0)))
            .norm() < 1e-12);
}

TEST_CASE("tool-side and instrument effects", "[effects]") {
  EffectModel fx{{Effect::parse("tool_offset_Z"), Effect::parse("linear_squareness_YZ"),
                  Effect::parse("linear_scale_X"), Effect::parse("ballbar_length_offset"),
                  Effect::parse("ballbar_thermal_drift")}};
  const std::vector<double> p = {0.01, 2e-5, 3e-5, 0.004, 1e-6};
  const Eigen::Vector3d xyz(200, 50, 100);
  const Eigen::Vector3d tool = tool_position<double>(fx, p.data(), xyz, 10.0);
  CHECK((tool - Eigen::Vector3d(200 + 3e-5 * 200, 50 + 2e-5 * 100, 100.01)).norm() < 1e-12);
  CHECK_THAT(ballbar_reading_error<double>(fx, p.data(), 10.0), WithinAbs(0.004 + 1e-5, 1e-15));
  CHECK(fx.param_labels()[0] == "tool_offset_Z.d");
  CHECK(fx.offset(4) == 4);
}

TEST_CASE("effect parameters are differentiable with ceres::Jet", "[effects][jet]") {
  using J = ceres::Jet<double, 12>;
  const auto m = MachineType::BC_trt;
  EffectModel fx{{Effect::parse("gravity_sag_B"), Effect::parse("coning_B"),
                  Effect::parse("tilt_motion_C_h1"), Effect::parse("radial_motion_B_h2"),
                  Effect::parse("angular_positioning_C_h1")}};
  REQUIRE(fx.num_params() == 12);
  std::vector<double> p = {0.006, 1e-4,  1e-5, -2e-5, 3e-5, 1e-5,
                           1e-3,  -2e-3, 5e-4, 1e-3,  1e-5, -1e-5};
  std::vector<J> pj(12);
  for (int i = 0; i < 12; ++i) pj[i] = J(p[i], i);
  const Eigen::Vector3d q(100, 30, 60);
  const RotaryAngles<double> a{0.8, 2.0};
  LocationErrors<double> e;
  e.v << 0.01, -0.02, 1e-5, 2e-5, 0.03, 0.01, -1e-5, 3e-5;
  const Vec3<J> pm = table_pose<J>(m, e.cast<J>(), fx, pj.data(), a, 0.0) * q.cast<J>();
  for (int i = 0; i < 12; ++i) {
    const double h = 1e-7;
    auto pp = p, pmn = p;
    pp[i] += h;
    pmn[i] -= h;
    const Eigen::Vector3d fd = (table_pose<double>(m, e, fx, pp.data(), a, 0.0) * q -
                                table_pose<double>(m, e, fx, pmn.data(), a, 0.0) * q) /
                               (2 * h);
    for (int k = 0; k < 3; ++k)
      CHECK_THAT(pm[k].v[i], WithinAbs(fd[k], 1e-5 * (1 + std::abs(fd[k]))));
  }
}

TEST_CASE("table_point agrees with table_pose for every stage", "[effects]") {
  const auto m = MachineType::AC_trt;
  EffectModel fx{{Effect::parse("thermal_drift_X"), Effect::parse("coning_A"),
                  Effect::parse("tilt_motion_A_h2"), Effect::parse("radial_motion_C_h2"),
                  Effect::parse("rotary_zero_offset_C")}};
  const std::vector<double> p = {1e-5, 1e-4, 1e-5,  2e-5, -1e-5, 3e-5,
                                 1e-3, 2e-3, -1e-3, 4e-4, 2e-4};
  REQUIRE(static_cast<int>(p.size()) == fx.num_params());
  LocationErrors<double> e;
  e.v << 0.01, -0.02, 1e-5, 2e-5, 0.03, 0.01, -1e-5, 3e-5;
  const Eigen::Vector3d q(120, 10, 60);
  for (double a : {-1.0, 0.3}) {
    const Eigen::Vector3d p1 = table_pose<double>(m, e, fx, p.data(), {a, 2.0}, 50.0) * q;
    const Eigen::Vector3d p2 = table_point<double>(m, e, fx, p.data(), {a, 2.0}, 50.0, q);
    CHECK((p1 - p2).norm() < 1e-12);
  }
  // With no effects both reduce to the baseline kinematics of machine.hpp.
  const EffectModel none;
  CHECK((table_point<double>(m, e, none, nullptr, {0.4, 1.0}, 0.0, q) -
         forward<double>(m, e, {0.4, 1.0}, q))
            .norm() < 1e-12);
}
