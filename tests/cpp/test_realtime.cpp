// SPDX-License-Identifier: BSD-3-Clause
// The real-time evaluation (include/rotacal/realtime/) against the fits' own evaluation of the
// same model (kinematics/effects.hpp: table_pose and tool_position, what the simulators call),
// with every catalogue term of the machine; the inverse's round trip and contraction over the
// travel; the blob through the library's reader. tests/realtime/standalone.cpp builds the
// headers alone (no exceptions, no RTTI, no library) and counts allocations.

#include <catch2/catch.hpp>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/io/realtime_export.hpp"
#include "rotacal/realtime/blob.hpp"
#include "rotacal/realtime/evaluate.hpp"

using namespace rotacal;

namespace {

MachineType machine_named(const std::string& name) {
  return MachineType::from_description(*builtin_machine(name));
}

// A model with every catalogue effect of m (harmonics 1 and 2) at random sizes of a real
// machine's (10 um, 20 urad), and random location errors of 50 um and 0.1 mrad.
struct TestModel {
  MachineType machine;
  LocationErrors<double> errors;
  EffectModel fx;
  std::vector<double> p;
};
TestModel every_term(MachineType m, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  TestModel t{m, {}, {}, {}};
  for (int i = 0; i < 8; ++i) t.errors.v[i] = (location_error_is_angle(i) ? 1e-4 : 0.05) * n(rng);
  t.fx.effects = effect_catalogue(m, 2);
  t.fx.linear_reference = Eigen::Vector3d(20, -10, 50);
  for (const Effect& f : t.fx.effects) {
    const std::vector<std::string> units = f.param_units();
    for (const std::string& u : units)
      t.p.push_back(u == "mm" ? 0.01 * n(rng) : u == "1" ? 0.3 * n(rng) : 2e-5 * n(rng));
  }
  return t;
}

RotaryMotion moving() {
  RotaryMotion mo;
  mo.rate = {0.2, -0.5};
  mo.direction = {1, -1};
  mo.since_reversal = {0.01, 0.03};
  return mo;
}

realtime::Joints random_joints(MachineType m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  realtime::Joints q;
  q.xyz = Eigen::Vector3d(200 * u(rng), 150 * u(rng), 100 + 80 * u(rng));
  q.angles = {1.5 * u(rng), 3.1 * u(rng)};
  (void)m;
  return q;
}

}  // namespace

TEST_CASE("forward equals the fits' evaluation of the same model, every term", "[realtime]") {
  std::mt19937 rng(55);
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table"}) {
    const MachineType m = machine_named(name);
    const TestModel t = every_term(m, rng);
    const realtime::Model rt = realtime_model(m, t.errors, t.fx, t.p, "test");
    const MachineDescription& d = m.description();
    realtime::State s;
    s.t = 400;
    s.motion = moving();
    s.tool_length = m.has_head() ? d.tool_length : 0.0;
    // The direction is the head's rotation; the carriage pitch moves the ball through its height
    // but turns nothing in the fits' model, so the two-length reference leaves it out.
    TestModel no_pitch = t;
    for (std::size_t i = 0, off = 0; i < t.fx.effects.size();
         off += t.fx.effects[i].num_params(), ++i)
      if (t.fx.effects[i].kind == EffectKind::linear_pitch)
        no_pitch.p[off] = no_pitch.p[off + 1] = 0.0;
    const realtime::Model rt_no_pitch = realtime_model(m, t.errors, t.fx, no_pitch.p, "test");
    double worst_tip = 0, worst_dir = 0;
    for (int i = 0; i < 200; ++i) {
      const realtime::Joints q = random_joints(m, rng);
      const Pose<double> T =
          table_pose<double>(m, t.errors, t.fx, t.p.data(), q.angles, s.t, s.motion);
      const Eigen::Vector3d ball =
          tool_position<double>(m, t.errors, t.fx, t.p.data(), q.xyz, q.angles, s.t, 0.0, s.motion);
      const realtime::ToolPose f = realtime::forward(rt, q, s);
      worst_tip = std::max(worst_tip, (f.tip - T.inverse() * ball).norm());
      // The tool's direction as the fits' model holds it: from the ball at two tool lengths
      // (on a table machine the spindle is the machine's Z).
      Eigen::Vector3d dir = Eigen::Vector3d::UnitZ();
      if (m.has_head()) {
        const auto at = [&](double dl) {
          return tool_position<double>(m, t.errors, t.fx, no_pitch.p.data(), q.xyz, q.angles, s.t,
                                       dl, s.motion);
        };
        dir = at(0.0) - at(1.0);
      }
      const realtime::ToolPose g = realtime::forward(rt_no_pitch, q, s);
      worst_dir = std::max(worst_dir, (g.direction - T.R.transpose() * dir).norm());
    }
    INFO(name << ": worst tip " << worst_tip * 1e6 << " nm, direction " << worst_dir * 1e9
              << " nrad");
    CHECK(worst_tip < 1e-9);
    CHECK(worst_dir < 1e-9);
  }
}

TEST_CASE("the tool length and the thermal states enter as the fits' terms", "[realtime]") {
  std::mt19937 rng(7);
  const MachineType m = machine_named("B-head-C-table");
  const TestModel t = every_term(m, rng);
  realtime::Model rt = realtime_model(m, t.errors, t.fx, t.p, "test");
  rt.thermal_gain(4, 0) = 0.004;  // E_X0B moves 4 um per unit of y1
  rt.thermal_gain(7, 1) = -3e-5;  // E_C0B by -30 urad per unit of y2
  realtime::State s;
  s.tool_length = m.description().tool_length + 12.5;
  s.y1 = 0.7;
  s.y2 = 0.25;
  LocationErrors<double> e = t.errors;
  e.v[4] += 0.004 * 0.7;
  e.v[7] += -3e-5 * 0.25;
  const realtime::Joints q = random_joints(m, rng);
  const Pose<double> T = table_pose<double>(m, e, t.fx, t.p.data(), q.angles, 0.0);
  const Eigen::Vector3d ball =
      tool_position<double>(m, e, t.fx, t.p.data(), q.xyz, q.angles, 0.0, 12.5);
  CHECK((realtime::forward(rt, q, s).tip - T.inverse() * ball).norm() < 1e-9);
}

TEST_CASE("inverse: round trip to 0.01 um and the contraction over the travel", "[realtime]") {
  std::mt19937 rng(11);
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table"}) {
    const MachineType m = machine_named(name);
    const TestModel t = every_term(m, rng);
    const realtime::Model rt = realtime_model(m, t.errors, t.fx, t.p, "test");
    const realtime::Model nominal = realtime::nominal_of(rt);
    realtime::State s;
    s.t = 400;
    s.tool_length = m.has_head() ? m.description().tool_length : 0.0;
    double worst_tip = 0, worst_dir = 0, worst_ratio = 0;
    for (int i = 0; i < 500; ++i) {
      realtime::Joints world = random_joints(m, rng);
      if (std::abs(world.angles.tilt) < 0.02) continue;  // the rotary axis is free at tilt 0
      world.xyz = Eigen::Vector3d(world.xyz.x(), world.xyz.y(), world.xyz.z() - 100);
      const realtime::InverseResult r = realtime::inverse(rt, world, s);
      const realtime::ToolPose f = realtime::forward(rt, r.joints, s);
      const realtime::ToolPose target = realtime::forward(nominal, world, s);
      worst_tip = std::max(worst_tip, (f.tip - world.xyz).norm());
      worst_dir = std::max(worst_dir, (f.direction - target.direction).norm());
      CHECK(r.tip_error == Approx((f.tip - world.xyz).norm()).margin(1e-12));
      // Contraction: the error after one step over the error of the nominal inverse.
      const realtime::InverseResult r0 = realtime::inverse(rt, world, s, 0);
      const realtime::InverseResult r1 = realtime::inverse(rt, world, s, 1);
      const double e0 = r0.tip_error + 100 * r0.direction_error;
      const double e1 = r1.tip_error + 100 * r1.direction_error;
      if (e0 > 1e-6) worst_ratio = std::max(worst_ratio, e1 / e0);
    }
    INFO(name << ": worst tip " << worst_tip * 1e3 << " um, direction " << worst_dir * 1e6
              << " urad, contraction per step " << worst_ratio);
    CHECK(worst_tip < 1e-5);
    CHECK(worst_dir < 1e-8);
    CHECK(worst_ratio < 0.1);  // the bound evaluate.hpp states for kInverseSteps
  }
}

TEST_CASE("the blob of a model reads back and is refused for another machine", "[realtime]") {
  std::mt19937 rng(3);
  const MachineType ac = MachineType::AC_trt;
  const TestModel t = every_term(ac, rng);
  const realtime::Model rt = realtime_model(ac, t.errors, t.fx, t.p, "test");
  const std::string blob = realtime::encode(rt);
  const realtime::Model back = read_realtime_blob(blob, &ac, "model.rtb");
  const realtime::Joints q = random_joints(ac, rng);
  CHECK((realtime::forward(back, q, {}).tip - realtime::forward(rt, q, {}).tip).norm() == 0.0);
  const MachineType bc = MachineType::BC_trt;
  CHECK_THROWS_WITH(read_realtime_blob(blob, &bc, "model.rtb"), Catch::Contains("model.rtb") &&
                                                                    Catch::Contains("machine") &&
                                                                    Catch::Contains("BC-trt"));
  std::string cut = blob.substr(0, blob.size() / 2);
  CHECK_THROWS_WITH(read_realtime_blob(cut, &ac, "model.rtb"), Catch::Contains("length"));
  // An effect the machine does not have cannot be exported.
  EffectModel wrong;
  wrong.effects = {Effect::parse("gravity_sag_B")};
  CHECK_THROWS_AS(realtime_model(ac, t.errors, wrong, {0.01}, "test"), InvalidArgument);
}

TEST_CASE("forward_world is the inverse's counterpart: joints -> world -> the same joints",
          "[realtime]") {
  std::mt19937 rng(17);
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table"}) {
    const MachineType m = machine_named(name);
    const TestModel t = every_term(m, rng);
    const realtime::Model rt = realtime_model(m, t.errors, t.fx, t.p, "test");
    realtime::State s;
    s.tool_length = m.has_head() ? m.description().tool_length : 25.0;
    double worst_xyz = 0, worst_angle = 0, worst_shift = 0;
    for (int i = 0; i < 300; ++i) {
      const realtime::Joints q = random_joints(m, rng);
      if (std::abs(q.angles.tilt) < 0.02) continue;  // the rotary axis is free at tilt 0
      const realtime::Joints w = realtime::forward_world(rt, q, s);
      const realtime::Joints back = realtime::inverse(rt, w, s).joints;
      worst_xyz = std::max(worst_xyz, (back.xyz - q.xyz).norm());
      worst_angle = std::max({worst_angle, std::abs(back.angles.tilt - q.angles.tilt),
                              std::abs(back.angles.rot - q.angles.rot)});
      // The world angles differ from the joints' by the model's angular errors, not by zero.
      worst_shift = std::max(worst_shift, std::abs(w.angles.rot - q.angles.rot));
    }
    INFO(name << ": worst xyz " << worst_xyz * 1e6 << " nm, angle " << worst_angle * 1e9
              << " nrad; world - joint angle up to " << worst_shift * 1e6 << " urad");
    CHECK(worst_xyz < 1e-5);
    CHECK(worst_angle < 1e-8);
    CHECK(worst_shift > 1e-6);
  }
}
