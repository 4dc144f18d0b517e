// SPDX-License-Identifier: BSD-3-Clause
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <random>

#include "rotacal/kinematics/machine.hpp"

using namespace rotacal;
using Catch::Matchers::WithinAbs;

namespace {
Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

LocationErrors<double> random_errors(std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  LocationErrors<double> e;
  for (int i = 0; i < 8; ++i) e.v[i] = location_error_is_angle(i) ? 5e-5 * N(rng) : 0.03 * N(rng);
  return e;
}
}  // namespace

TEST_CASE("nominal forward kinematics is Rx(A) Rz(C) q and Ry(B) Rz(C) q", "[machine]") {
  const Eigen::Vector3d q(120, -30, 60);
  const LocationErrors<double> zero;
  for (double t : {-1.2, 0.0, 0.5}) {
    for (double c : {0.0, 1.0, -2.5}) {
      CHECK((forward(MachineType::AC_trt, zero, {t, c}, q) - Rx(t) * Rz(c) * q).norm() < 1e-12);
      CHECK((forward(MachineType::BC_trt, zero, {t, c}, q) - Ry(t) * Rz(c) * q).norm() < 1e-12);
    }
  }
}

TEST_CASE("names, parsing and order of location errors", "[machine]") {
  CHECK(parse_machine_type("AC-trt") == MachineType::AC_trt);
  CHECK(parse_machine_type("BC-trt") == MachineType::BC_trt);
  CHECK_THROWS_AS(parse_machine_type("XY-trt"), InvalidArgument);
  CHECK_THROWS_WITH(parse_machine_type("XY-trt"), Catch::Contains("XY-trt"));
  CHECK(location_error_names(MachineType::AC_trt)[0] == "E_Y0A");
  CHECK(location_error_names(MachineType::BC_trt)[3] == "E_C0B");
  CHECK(location_error_index(MachineType::AC_trt, "E_B0C") == 7);
  CHECK_THROWS_AS(location_error_index(MachineType::AC_trt, "E_X0B"), InvalidArgument);
}

TEST_CASE("each location error moves the axis line as formats.md says", "[machine]") {
  // An offset of the C line by E_X0C: a point on the nominal C axis turns about (E_X0C, E_Y0C).
  LocationErrors<double> e;
  e.v[4] = 0.1;  // E_X0C
  const Eigen::Vector3d q(0, 0, 50);
  const Eigen::Vector3d p = forward(MachineType::AC_trt, e, {0.0, M_PI}, q);
  CHECK((p - Eigen::Vector3d(0.2, 0, 50)).norm() < 1e-12);
  // E_B0A tilts A's direction to (1, 0, -E_B0A): a point at x = 100 on the A axis rises by
  // -E_B0A * 100 * (1 - cos A) ... check instead that the actual A line is invariant.
  LocationErrors<double> f;
  f.v[2] = 1e-3;  // E_B0A
  f.v[1] = 0.05;  // E_Z0A
  const AxisLine<double> A = tilt_axis_line(MachineType::AC_trt, f);
  const Eigen::Vector3d on_line = A.point + 150.0 * A.direction;
  CHECK((forward(MachineType::AC_trt, f, {0.8, 0.0}, on_line) - on_line).norm() < 1e-12);
  CHECK(A.direction.z() == -1e-3);
  // BC: B line through (E_X0B, 0, E_Z0B) along (-E_C0B, 1, E_A0B).
  LocationErrors<double> g;
  g.v << 0.01, 0.02, 3e-4, 4e-4, 0, 0, 0, 0;
  const AxisLine<double> B = tilt_axis_line(MachineType::BC_trt, g);
  CHECK(B.point.isApprox(Eigen::Vector3d(0.01, 0, 0.02)));
  CHECK(B.direction.isApprox(Eigen::Vector3d(-4e-4, 1, 3e-4)));
}

TEST_CASE("inverse puts the ball where it was asked, nominal and with errors", "[machine]") {
  std::mt19937 rng(3);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    const LocationErrors<double> e = random_errors(rng);
    const Eigen::Vector3d p(120, 10, 160);
    const MachineAxes ax = inverse(m, e, {0.3, -1.0}, p);
    const Pose<double> T = table_pose(m, e, ax.angles);
    CHECK((T.inverse() * ax.xyz - p).norm() < 1e-12);
  }
}

TEST_CASE("inverse_with_tool_axis aligns the table direction with the spindle", "[machine]") {
  std::mt19937 rng(11);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    for (const LocationErrors<double>& e : {LocationErrors<double>(), random_errors(rng)}) {
      for (bool pos : {true, false}) {
        const Eigen::Vector3d k = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
        const Eigen::Vector3d p(50, 20, 30);
        const MachineAxes ax = inverse_with_tool_axis(m, e, p, k, pos);
        const Pose<double> T = table_pose(m, e, ax.angles);
        CHECK((T.R * k - Eigen::Vector3d::UnitZ()).norm() < 1e-12);
        CHECK((T * p - ax.xyz).norm() < 1e-12);
        CHECK((ax.angles.tilt >= 0) == pos);
      }
    }
  }
  CHECK_THROWS_AS(inverse_with_tool_axis(MachineType::AC_trt, {}, {0, 0, 0}, {0, 0, 0}),
                  InvalidArgument);
}

TEST_CASE("forward kinematics is differentiable in the errors with ceres::Jet", "[machine][jet]") {
  using J = ceres::Jet<double, 8>;
  std::mt19937 rng(5);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    const LocationErrors<double> e = random_errors(rng);
    LocationErrors<J> ej;
    for (int i = 0; i < 8; ++i) ej.v[i] = J(e.v[i], i);
    const Eigen::Vector3d q(120, 5, 60);
    const RotaryAngles<double> a{0.7, 2.1};
    const Vec3<J> pj = forward<J>(m, ej, {J(a.tilt), J(a.rot)}, q.cast<J>());
    for (int i = 0; i < 8; ++i) {
      const double h = location_error_is_angle(i) ? 1e-7 : 1e-5;
      LocationErrors<double> ep = e, em = e;
      ep.v[i] += h;
      em.v[i] -= h;
      const Eigen::Vector3d fd = (forward(m, ep, a, q) - forward(m, em, a, q)) / (2 * h);
      for (int k = 0; k < 3; ++k)
        CHECK_THAT(pj[k].v[i], WithinAbs(fd[k], 1e-5 * (1 + std::abs(fd[k]))));
    }
  }
}
