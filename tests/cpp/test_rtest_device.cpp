// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/device.hpp: probe model, direction calibration, sphere offset, raw conversion.
#include <catch2/catch.hpp>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/rtest/device.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
// Three probes roughly along the diagonals of a nest, as on commercial R-test heads.
Eigen::Matrix3d nest_dirs() {
  Eigen::Matrix3d D;
  D.row(0) = Eigen::Vector3d(0.8, 0.05, -0.6).normalized().transpose();
  D.row(1) = Eigen::Vector3d(-0.4, 0.7, -0.6).normalized().transpose();
  D.row(2) = Eigen::Vector3d(-0.4, -0.72, -0.55).normalized().transpose();
  return D;
}
}  // namespace

TEST_CASE("flat probes: readings <-> displacement round trip") {
  const Eigen::Matrix3d D = nest_dirs();
  const Eigen::Vector3d d(0.012, -0.034, 0.021);
  const Eigen::Vector3d r = probe_readings<double>(D, d);
  // Each reading is the projection on its own direction (the flat-probe model).
  for (int i = 0; i < 3; ++i) CHECK(r[i] == Approx(D.row(i).dot(d)).margin(1e-15));
  CHECK((sphere_displacement(D, r) - d).norm() < 1e-14);
  Eigen::Matrix3d bad = D;
  bad.row(2) = D.row(0);
  CHECK_THROWS_AS(sphere_displacement(bad, r), DegenerateGeometry);
}

TEST_CASE("probe directions are recovered from known linear moves within their uncertainty") {
  const Eigen::Matrix3d D = nest_dirs();
  const Eigen::Vector3d zeros(0.11, -0.05, 0.3);
  const double noise_um = 0.3;
  const auto moves = default_calibration_moves(0.5);
  const auto samples = simulate_probe_calibration(D, zeros, moves, noise_um, 7);
  const ProbeCalibration cal = calibrate_probe_directions(samples);
  // Residual sigma estimates the simulated noise (dof = 3*(14-4) = 30: +-40% is > 3 sigma).
  CHECK(cal.sigma_um == Approx(noise_um).epsilon(0.4));
  for (int i = 0; i < 3; ++i) {
    const double angle = std::acos(std::min(1.0, cal.dirs.row(i).dot(D.row(i))));
    // The reported angular std is about noise / (step * sqrt(n/3)) ~ 1 mrad; 4 sigma bound.
    CHECK(cal.direction_std_rad[i] > 0.0);
    CHECK(cal.direction_std_rad[i] < 3e-3);
    CHECK(angle < 4.0 * cal.direction_std_rad[i]);
    CHECK(std::abs(cal.gains[i] - 1.0) < 4.0 * cal.gain_std[i]);
    // zero std ~ noise / sqrt(14) (the moves are centred); 6 sigma bound.
    CHECK(std::abs(cal.zeros[i] - zeros[i]) < 6.0 * noise_um * 1e-3 / std::sqrt(14.0));
  }
  std::vector<ProbeCalibrationSample> few(samples.begin(), samples.begin() + 4);
  CHECK_THROWS_AS(calibrate_probe_directions(few), InvalidArgument);
  std::vector<ProbeCalibrationSample> flat = samples;
  for (auto& s : flat) s.move.z() = 0.0;
  CHECK_THROWS_AS(calibrate_probe_directions(flat), DegenerateGeometry);
}

TEST_CASE("sphere offset from spindle indexing") {
  const Eigen::Matrix3d D = nest_dirs();
  const Eigen::Vector2d offset(0.0123, -0.0081);
  std::vector<double> angles;
  for (int k = 0; k < 8; ++k) angles.push_back(k * M_PI / 4.0);
  const double noise_um = 0.3;
  const auto s = simulate_spindle_indexing(D, Eigen::Vector3d(0.1, 0.2, -0.1), offset,
                                           Eigen::Vector3d(0.01, 0.02, -0.03), angles, noise_um, 3);
  const SphereOffsetCalibration cal = calibrate_sphere_offset(D, s);
  // Noise on d is ~ noise * |Dirs^-1| ~ 2x per axis; offset std ~ that / sqrt(n/2) ~ 0.3 um.
  for (int k = 0; k < 2; ++k) {
    CHECK(cal.offset_std[k] > 0.0);
    CHECK(cal.offset_std[k] < 1e-3);
    CHECK(std::abs(cal.offset[k] - offset[k]) < 4.0 * cal.offset_std[k]);
  }
  // Noise-free: exact.
  const auto s0 = simulate_spindle_indexing(D, Eigen::Vector3d::Zero(), offset,
                                            Eigen::Vector3d::Zero(), angles, 0.0, 3);
  CHECK((calibrate_sphere_offset(D, s0).offset - offset).norm() < 1e-12);
  CHECK_THROWS_AS(calibrate_sphere_offset(D, {s[0], s[1]}), InvalidArgument);
}

TEST_CASE("sessions with raw readings are converted with probe.N.dir") {
  const Eigen::Matrix3d D = nest_dirs();
  RtestSession session;
  for (int k = 1; k <= 3; ++k) session.probe_dirs[k] = D.row(k - 1).transpose();
  RtestSample s;
  s.setup = "1";
  s.raw = Eigen::Vector3d(0.01, -0.02, 0.005);
  session.samples.push_back(s);
  s.raw.reset();
  s.d = Eigen::Vector3d(1, 2, 3);
  session.samples.push_back(s);
  const RtestSession out = displacements_from_raw(session);
  REQUIRE(out.samples[0].d.has_value());
  CHECK((D * *out.samples[0].d - *session.samples[0].raw).norm() < 1e-14);
  CHECK((*out.samples[1].d - Eigen::Vector3d(1, 2, 3)).norm() == 0.0);
  RtestSession missing = session;
  missing.probe_dirs.erase(2);
  CHECK_THROWS_AS(displacements_from_raw(missing), InvalidArgument);
  CHECK_THROWS_WITH(displacements_from_raw(missing), Catch::Contains("'# probe.2.dir: x, y, z'"));
}

TEST_CASE("sphere offset compensation removes R^T o from every displacement") {
  RtestSession session;
  RtestSample s;
  s.setup = "1";
  s.tilt_deg = 90.0;
  s.rot_deg = 0.0;
  s.d = Eigen::Vector3d::Zero();
  session.samples.push_back(s);
  const RtestSession out = compensate_sphere_offset(session, Eigen::Vector2d(0.01, 0.0));
  // Ry(90)^T e_x = e_z: a sphere shifted by +x appears at +z in the table frame; it is removed.
  CHECK((*out.samples[0].d - Eigen::Vector3d(0, 0, -0.01)).norm() < 1e-15);
}

TEST_CASE("sphere offset compensation on a head machine follows the spindle", "[any_machine]") {
  // A sphere 10 um off the spindle axis along the spindle's X (tool_offset_X turns with the
  // head there): compensating it gives the session of a centred sphere.
  for (const char* name : {"B-head-C-table", "AC-head", "B45C-trt"}) {
    INFO(name);
    const MachineType m = parse_machine_type(name);
    MachineModel centred = MachineModel::nominal(m), off = MachineModel::nominal(m);
    off.effects.effects.push_back(Effect::parse("tool_offset_X"));
    off.effect_params.push_back(0.01);
    RtestSimOptions o;
    o.pattern = default_rtest_pattern(m);
    o.noise_um = 0.0;
    const RtestSession a = simulate_rtest(centred, o).session;
    const RtestSession b =
        compensate_sphere_offset(simulate_rtest(off, o).session, Eigen::Vector2d(0.01, 0.0));
    double worst = 0.0;
    for (std::size_t i = 0; i < a.samples.size(); ++i)
      worst = std::max(worst, (*a.samples[i].d - *b.samples[i].d).norm());
    CHECK(worst < 1e-12);
  }
}
