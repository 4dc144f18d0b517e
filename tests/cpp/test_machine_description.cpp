// SPDX-License-Identifier: BSD-3-Clause
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "rotacal/kinematics/machine.hpp"

using namespace rotacal;

namespace {

LocationErrors<double> random_errors(std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  LocationErrors<double> e;
  for (int i = 0; i < 8; ++i) e.v[i] = location_error_is_angle(i) ? 5e-5 * N(rng) : 0.03 * N(rng);
  return e;
}

double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

// A random pose inside the axis limits (endless axes: +-180 deg), tilt at least 5 deg from 0.
RotaryAngles<double> random_pose(MachineType m, std::mt19937& rng) {
  auto range = [&](int k) {
    const auto& lim = m.description().axis(k).limits_deg;
    return lim ? *lim : std::array<double, 2>{-180.0, 180.0};
  };
  const auto t = range(m.tilt_index()), r = range(m.rot_index());
  std::uniform_real_distribution<double> U(0.0, 1.0);
  RotaryAngles<double> a;
  do a.tilt = (t[0] + (t[1] - t[0]) * U(rng)) * M_PI / 180.0;
  while (std::abs(a.tilt) < 5.0 * M_PI / 180.0 || std::abs(a.tilt) > 175.0 * M_PI / 180.0);
  a.rot = (r[0] + (r[1] - r[0]) * U(rng)) * M_PI / 180.0;
  return a;
}

const char* kAcJson = R"({"format": "rotacal-machine/1", "name": "my AC table",
  "table_axes": [{"name": "A", "direction": [1, 0, 0], "limits_deg": [-120, 30]},
                 {"name": "C", "direction": [0, 0, 1]}]})";

}  // namespace

TEST_CASE("built-in machines: configuration, tilt and rotary axes, error names",
          "[machine_description]") {
  const MachineType bh = parse_machine_type("B-head-C-table");
  CHECK(bh.description().configuration() == "head-table");
  CHECK(tilt_axis_letter(bh) == 'B');
  CHECK(rot_axis_letter(bh) == 'C');
  const std::array<std::string, 8> bh_names = {"E_X0C", "E_Y0C", "E_A0C", "E_B0C",
                                               "E_X0B", "E_Z0B", "E_A0B", "E_C0B"};
  CHECK(location_error_names(bh) == bh_names);
  const MachineType fork = parse_machine_type("AC-head");
  CHECK(fork.description().configuration() == "head-head");
  CHECK(tilt_axis_letter(fork) == 'A');
  CHECK(location_error_names(fork)[4] == "E_Y0A");
  const MachineType nut = parse_machine_type("B45C-trt");
  CHECK(location_error_names(nut)[0] == "E_U0B");
  CHECK(location_error_names(nut)[3] == "E_DV0B");
  CHECK(tilt_axis_letter(nut) == 'B');
  CHECK(to_string(MachineType::AC_trt) == "AC-trt");
  CHECK(MachineType::AC_trt.is_builtin());
  CHECK_THROWS_WITH(parse_machine_type("XY-trt"), Catch::Contains("B-head-C-table"));
}

TEST_CASE("a nutating axis: u, v as formats.md defines them", "[machine_description]") {
  const RotaryAxis a = make_rotary_axis('B', Eigen::Vector3d(0, -1, 1), Eigen::Vector3d::Zero(),
                                        false, std::nullopt, "test");
  // e = +X (|X . n| = 0 <= 0.5): u = unit(X x n), v = n x u.
  const Eigen::Vector3d n = Eigen::Vector3d(0, -1, 1).normalized();
  const Eigen::Vector3d u = Eigen::Vector3d::UnitX().cross(n).normalized();
  CHECK((a.position_basis.col(0) - u).norm() < 1e-15);
  CHECK((a.position_basis.col(1) - n.cross(u)).norm() < 1e-15);
  CHECK((a.direction_basis - a.position_basis).norm() == 0.0);
  CHECK(a.principal == -1);
  // A letter that does not match its direction takes the U/V names too.
  const RotaryAxis b = make_rotary_axis('A', Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero(),
                                        true, std::nullopt, "test");
  CHECK(b.error_names[0] == "E_U0A");
}

TEST_CASE("an axis along -X keeps the meaning of its error names", "[machine_description]") {
  const RotaryAxis plus = make_rotary_axis('A', Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero(),
                                           false, std::nullopt, "t");
  const RotaryAxis minus = make_rotary_axis('A', -Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero(),
                                            false, std::nullopt, "t");
  const Eigen::Vector2d o(2e-4, -3e-4);  // E_B0A, E_C0A
  const Eigen::Vector3d dp = plus.direction + plus.direction_basis * o;
  const Eigen::Vector3d dm = minus.direction + minus.direction_basis * o;
  // The same tilted line, run the other way.
  CHECK((dp.normalized() + dm.normalized()).norm() < 1e-15);
  CHECK(plus.error_names == minus.error_names);
}

TEST_CASE("a huge direction is normalised, not overflowed to zero", "[machine_description]") {
  // Issue 32: [1e200, 1e200, 0] had norm() = inf, so direction / norm was the zero vector.
  const RotaryAxis a = make_rotary_axis('A', Eigen::Vector3d(1e200, 0, 0), Eigen::Vector3d::Zero(),
                                        false, std::nullopt, "t");
  CHECK(a.direction == Eigen::Vector3d::UnitX());
  CHECK(a.principal == 0);
  const RotaryAxis u = make_rotary_axis('B', Eigen::Vector3d(1e200, 1e200, 0),
                                        Eigen::Vector3d::Zero(), false, std::nullopt, "t");
  CHECK(std::abs(u.direction.norm() - 1.0) < 1e-15);
  CHECK(std::abs(u.direction.x() - std::sqrt(0.5)) < 1e-15);
  CHECK_THROWS_AS(make_rotary_axis('A', Eigen::Vector3d(1e-300, 0, 0), Eigen::Vector3d::Zero(),
                                   false, std::nullopt, "t"),
                  InvalidArgument);
}

TEST_CASE("a description written out for AC-trt and BC-trt moves exactly like the built-in",
          "[machine_description]") {
  std::mt19937 rng(7);
  for (MachineType b : {MachineType::AC_trt, MachineType::BC_trt}) {
    MachineDescription d =
        parse_machine_description(machine_description_json(b.description()), "round trip");
    CHECK(MachineType::from_description(d) == b);  // same name and kinematics: the built-in
    d.name = "custom copy";
    const MachineType c = MachineType::from_description(d);
    CHECK(c != b);
    CHECK(location_error_names(c) == location_error_names(b));
    for (int i = 0; i < 20; ++i) {
      const LocationErrors<double> e = random_errors(rng);
      const RotaryAngles<double> a{0.3 * i - 3.0, 0.7 * i};
      const Eigen::Vector3d q(100.0 - i, 20.0 * i - 50, 60);
      CHECK((forward(c, e, a, q) - forward(b, e, a, q)).norm() < 1e-12);
    }
  }
}

TEST_CASE("inverse(forward) returns the pose on every built-in machine", "[machine_description]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-150.0, 150.0);
  for (const std::string& name : builtin_machine_names()) {
    const MachineType m = parse_machine_type(name);
    INFO(name);
    for (int i = 0; i < 60; ++i) {
      const LocationErrors<double> e = i % 2 ? random_errors(rng) : LocationErrors<double>();
      const RotaryAngles<double> a = random_pose(m, rng);
      const Eigen::Vector3d xyz(U(rng), U(rng), U(rng) + 200.0);
      const Eigen::Vector3d p_table = ball_in_table(m, e, a, xyz);
      const Eigen::Vector3d k_table = table_pose(m, e, a).R.transpose() * tool_direction(m, e, a);
      const MachineAxes back = inverse_with_tool_axis(m, e, p_table, k_table, a.tilt > 0, a.rot);
      CHECK(std::abs(wrap(back.angles.tilt - a.tilt)) < 1e-9);
      CHECK(std::abs(wrap(back.angles.rot - a.rot)) < 1e-9);
      CHECK((back.xyz - xyz).norm() < 1e-9);
      // And the ball-only inverse at the given angles.
      CHECK((inverse(m, e, a, p_table).xyz - xyz).norm() < 1e-9);
    }
  }
}

TEST_CASE("head kinematics pass Ceres Jets and agree with finite differences",
          "[machine_description]") {
  using J = ceres::Jet<double, 9>;
  std::mt19937 rng(3);
  for (const char* name : {"B-head-C-table", "AC-head", "B45C-trt"}) {
    const MachineType m = parse_machine_type(name);
    const LocationErrors<double> e = random_errors(rng);
    const RotaryAngles<double> a{0.6, -1.1};
    const Eigen::Vector3d xyz(40, -20, 300), q(80, 30, 50);
    LocationErrors<J> ej;
    for (int k = 0; k < 8; ++k) ej.v[k] = J(e.v[k], k);
    const J dl(0.01, 8);
    const RotaryAngles<J> aj{J(a.tilt), J(a.rot)};
    const Vec3<J> d =
        tool_ball<J>(m, ej, aj, xyz.cast<J>(), dl) - forward<J>(m, ej, aj, q.cast<J>());
    for (int k = 0; k < 9; ++k) {
      const double h = k < 8 && location_error_is_angle(k) ? 1e-7 : 1e-5;
      LocationErrors<double> ep = e, em = e;
      double lp = 0.01, lm = 0.01;
      if (k < 8)
        ep.v[k] += h, em.v[k] -= h;
      else
        lp += h, lm -= h;
      const Eigen::Vector3d fd = ((tool_ball(m, ep, a, xyz, lp) - forward(m, ep, a, q)) -
                                  (tool_ball(m, em, a, xyz, lm) - forward(m, em, a, q))) /
                                 (2 * h);
      for (int r = 0; r < 3; ++r)
        CHECK(std::abs(d[r].v[k] - fd[r]) < 1e-5 * (1.0 + std::abs(fd[r])));
    }
  }
}

TEST_CASE("bad machine descriptions are refused with the field named", "[machine_description]") {
  auto refuses = [](const std::string& text, const std::string& what) {
    INFO(text);
    CHECK_THROWS_AS(parse_machine_description(text, "m.json"), InvalidArgument);
    CHECK_THROWS_WITH(parse_machine_description(text, "m.json"),
                      Catch::Contains("m.json") && Catch::Contains(what));
  };
  const std::string head = R"({"format": "rotacal-machine/1", )";
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [0, 0, 0]}, {"name": "C", "direction": [0, 0, 1]}]})",
      "table_axes[0].direction is zero");
  refuses(
      head +
          R"("table_axes": [{"name": "C", "direction": [1, 0, 0]}, {"name": "C", "direction": [0, 0, 1]}]})",
      "named 'C'");
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [1, 0, 0]}, {"name": "B", "direction": [0, 1, 0]},
          {"name": "C", "direction": [0, 0, 1]}]})",
      "at most 2 per side");
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [1, 0, 0]}], "head_axes": [{"name": "W", "direction": [0, 0, 1]}]})",
      "head_axes[0].name 'W'");
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [1, 0, 1e999]}, {"name": "C", "direction": [0, 0, 1]}]})",
      "number overflow parsing '1e999'");
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [1, 0, NaN]}, {"name": "C", "direction": [0, 0, 1]}]})",
      "not valid JSON");
  refuses(head + R"("table_axes": [{"name": "A", "direction": [1, 0, 0]}]})", "hold 1 rotary axes");
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [1, 0, 0], "limits_deg": [30, -120]}, {"name": "C", "direction": [0, 0, 1]}]})",
      "limits_deg must have min < max");
  refuses(
      head +
          R"("table_axes": [{"name": "A", "direction": [0, 0, 1]}, {"name": "C", "direction": [0, 0, -1]}]})",
      "parallel");
  refuses(head + R"("tabel_axes": []})", "tabel_axes is not a field");
  refuses(R"({"format": "rotacal-machine/2"})", "format");
  // Built in memory (no JSON to stop it), a NaN is refused where the axis is made.
  CHECK_THROWS_WITH(make_rotary_axis('A', Eigen::Vector3d(1, 0, std::nan("")),
                                     Eigen::Vector3d::Zero(), false, std::nullopt, "axes[0]"),
                    Catch::Contains("axes[0]") && Catch::Contains("finite"));
  // A valid one parses, with its limits.
  const MachineDescription d = parse_machine_description(kAcJson, "ac.json");
  REQUIRE(d.table_axes[0].limits_deg);
  CHECK((*d.table_axes[0].limits_deg)[0] == -120.0);
  CHECK(d.name == "my AC table");
}
