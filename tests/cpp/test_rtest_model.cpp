// SPDX-License-Identifier: BSD-3-Clause
// Tests of the one R-test reading (rtest/model.hpp) against the other routes to the same
// number: machine.hpp's table pose, the joint model with zero maps, Oyama's HTM form.
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <random>

#include "rotacal/rtest/error_model.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/model.hpp"

using namespace rotacal;

namespace {
MachineModel random_bc(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  MachineModel m;
  m.machine = MachineType::BC_trt;
  for (int i = 0; i < 8; ++i)
    m.errors.v[i] = location_error_is_angle(i) ? 5e-5 * N(rng) : 0.02 * N(rng);
  return m;
}
}  // namespace

TEST_CASE("a perfect machine reads zero everywhere", "[rtest_model]") {
  MachineModel m;
  m.machine = MachineType::BC_trt;
  for (double B : {-1.5, -0.5, 0.0, 0.7, 1.5})
    for (double C : {0.0, 1.0, 2.5, 4.0})
      CHECK(rtest_reading(m, Eigen::Vector3d(100, -20, 60), {B, C}, 3.0).norm() < 1e-12);
}

TEST_CASE("the reading equals T^-1 xyz - q with machine.hpp's table pose", "[rtest_model]") {
  std::mt19937_64 rng(7);
  const Eigen::Vector3d q(100, 0, 60);
  for (int k = 0; k < 5; ++k) {
    const MachineModel m = random_bc(rng);
    for (double B : {-1.2, 0.3, 1.5})
      for (double C : {0.0, 2.0, 5.0}) {
        const Eigen::Vector3d xyz =
            forward<double>(MachineType::BC_trt, LocationErrors<double>(), {B, C}, q);
        const Pose<double> T = table_pose<double>(MachineType::BC_trt, m.errors, {B, C});
        const Eigen::Vector3d expect = T.inverse() * xyz - q;
        CHECK((rtest_reading(m, q, {B, C}, 0.0) - expect).norm() < 1e-12);
        // The joint model with zero maps is the same machine.
        const Eigen::Vector3d joint = rtest_joint_reading<double>(
            m.errors, AxisErrors<double>::Zero(), AxisErrors<double>::Zero(), B, C, xyz, q);
        CHECK((joint - expect).norm() < 1e-12);
      }
  }
}

TEST_CASE("Oyama's constant errors read like the location errors", "[rtest_model]") {
  // oyama_from_location: T(e) = T_oyama F exactly, so with u = T_oyama^-1 xyz (Oyama's reading
  // of the nest at q, plus q) the location-error reading is F^-1 u - q: a constant shift per
  // nest (the probe zero) up to F's urad rotation of the um readings.
  std::mt19937_64 rng(9);
  const MachineModel m = random_bc(rng);
  const OyamaConstantErrors o = oyama_from_location(m.errors);
  const Eigen::Vector3d q(0, -120, 140);
  for (double B : {-1.0, 0.0, 0.8})
    for (double C : {0.0, 1.5, 3.0, 4.5}) {
      const Eigen::Vector3d u = oyama_displacement<double>(o.w_BY, o.w_CB, B, C, q) + q;
      const Eigen::Vector3d expect = o.F.inverse() * u - q;
      CHECK((rtest_reading(m, q, {B, C}, 0.0) - expect).norm() < 1e-10);
    }
}

TEST_CASE("Jets pass through the reading with effects", "[rtest_model]") {
  using J = ceres::Jet<double, 9>;
  MachineModel m;
  m.machine = MachineType::BC_trt;
  m.effects.effects = {Effect::parse("coning_B")};
  m.effect_params = {1.5e-4};
  std::mt19937_64 rng(4);
  m.errors = random_bc(rng).errors;
  LocationErrors<J> e;
  for (int i = 0; i < 8; ++i) e.v[i] = J(m.errors.v[i], i);
  const J k(m.effect_params[0], 8);
  const Eigen::Vector3d q(100, 0, 60), xyz(30, 40, 90);
  const RotaryAngles<double> a{0.7, 2.1};
  const Vec3<J> d = rtest_reading<J>(MachineType::BC_trt, e, m.effects, &k, xyz, a, 5.0, q);
  for (int j = 0; j < 9; ++j) {
    MachineModel p = m, n = m;
    const double h = 1e-7;
    if (j < 8)
      p.errors.v[j] += h, n.errors.v[j] -= h;
    else
      p.effect_params[0] += h, n.effect_params[0] -= h;
    const auto read = [&](const MachineModel& mm) {
      return rtest_reading<double>(mm.machine, mm.errors, mm.effects, mm.effect_data(), xyz, a, 5.0,
                                   q);
    };
    const Eigen::Vector3d fd = (read(p) - read(n)) / (2 * h);
    for (int r = 0; r < 3; ++r) CHECK(d[r].v[j] == Approx(fd[r]).margin(1e-6));
  }
}
