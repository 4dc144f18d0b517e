// SPDX-License-Identifier: BSD-3-Clause
// Tests of MachineModel: validation naming the field, parameter names, and that both
// instruments' models are one.
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/kinematics/machine_model.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

TEST_CASE("MachineModel validation names what is wrong", "[machine_model]") {
  MachineModel m;
  m.machine = MachineType::AC_trt;
  m.effects.effects = {Effect::parse("gravity_sag_A"), Effect::parse("radial_motion_C_h2")};
  m.effect_params = {0.004, 0.001, 0.0, 0.0};
  CHECK_THROWS_WITH(m.validate("truth"),
                    Catch::Contains("truth.effect_params") && Catch::Contains("5"));
  m.effect_params.push_back(0.0);
  CHECK_NOTHROW(m.validate("truth"));
  m.effect_params[2] = std::nan("");
  CHECK_THROWS_WITH(m.validate("truth"), Catch::Contains("effect_params[2]"));
  m.effect_params[2] = 0.0;
  m.errors.v[5] = INFINITY;
  CHECK_THROWS_WITH(m.validate("truth"), Catch::Contains("E_Y0C"));
  m.errors.v[5] = 0.0;
  m.machine = MachineType::BC_trt;  // gravity sag of an A table on a B machine
  CHECK_THROWS_WITH(m.validate("truth"),
                    Catch::Contains("gravity_sag_A") && Catch::Contains("BC-trt"));
  CHECK_THROWS_AS(m.validate("truth"), InvalidArgument);
}

TEST_CASE("MachineModel parameter names: location errors, then effect parameters",
          "[machine_model]") {
  MachineModel m;
  m.machine = MachineType::BC_trt;
  m.effects.effects = {Effect::parse("coning_B"), Effect::parse("axial_motion_C_h1")};
  m.effect_params = {1e-4, 0.0, 0.0};
  const std::vector<std::string> n = m.parameter_names();
  REQUIRE(n.size() == 11);
  CHECK(n[0] == "E_X0B");
  CHECK(n[7] == "E_B0C");
  CHECK(n[8].find("coning_B") == 0);
  CHECK(n[10].find("axial_motion_C_h1") == 0);
  CHECK(m.effect_data() == m.effect_params.data());
  CHECK(MachineModel().effect_data() == nullptr);
}

TEST_CASE("the ballbar and R-test truths are the same MachineModel", "[machine_model]") {
  MachineModel m;
  m.machine = MachineType::BC_trt;
  m.errors.v << 0.01, -0.02, 3e-5, -2e-5, 0.015, -0.01, 1e-5, -4e-5;
  m.effects.effects = {Effect::parse("gravity_sag_B")};
  m.effect_params = {0.005};
  const MachineModel nominal = MachineModel::nominal(MachineType::BC_trt);
  CHECK(nominal.machine == MachineType::BC_trt);
  CHECK(nominal.errors.v.isZero());
  CHECK(nominal.effects.effects.empty());
  BallbarMachineModel bb;
  static_cast<MachineModel&>(bb) = m;  // a ballbar model is a MachineModel and its pivot
  bb.pivot = Eigen::Vector3d(100, 0, 50);
  // The same machine seen by both instruments: simulate_rtest refuses a bad model by name.
  MachineModel bad = m;
  bad.effect_params.clear();
  CHECK_THROWS_WITH(simulate_rtest(bad), Catch::Contains("effect_params"));
  CHECK_NOTHROW(simulate_rtest(m));
  BallbarSample s;
  s.xyz = Eigen::Vector3d(100, 0, 150);
  const std::vector<double> L = predict_lengths(bb, {s});
  REQUIRE(L.size() == 1);
  CHECK(std::isfinite(L[0]));
  CHECK(L[0] == Approx(100.0).margin(0.1));
}
