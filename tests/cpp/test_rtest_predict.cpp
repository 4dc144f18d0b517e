// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/predict.hpp: a model rebuilt from its parts, and held-out poses predicted
// against the simulator's noise-free truth with honest 1-sigma columns.
#include <catch2/catch.hpp>
#include <iostream>
#include <sstream>

#include "../support/synthetic_sessions.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/predict.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
MachineModel truth() {  // rtest_bc_oyama.truth.json + a C-axis face runout (2 lobes)
  MachineModel t = synthetic::oyama_truth();
  t.effects.effects.push_back(Effect::parse("axial_motion_C_h2"));
  t.effect_params.insert(t.effect_params.end(), {0.002, -0.001});
  return t;
}
// Rows of `s` whose C is (or is not) a multiple of 30 deg.
RtestSession rows_where(const RtestSession& s, bool on_30) {
  RtestSession out = s;
  out.samples.clear();
  for (const RtestSample& r : s.samples)
    if ((std::fmod(r.rot_deg, 30.0) == 0.0) == on_30) out.samples.push_back(r);
  return out;
}
}  // namespace

TEST_CASE("make_rtest_joint_model checks the parts against the basis") {
  RtestBasis b;
  const Eigen::Index n = 8 + b.num_b_coefficients() + b.num_c_coefficients();
  const Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
  const Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  const std::vector<bool> obs(static_cast<std::size_t>(n), true);
  CHECK_NOTHROW(make_rtest_joint_model(MachineType::BC_trt, b, p, C, obs));
  // Any machine: a table machine has the same layout; a machine with head axes adds
  // tool_offset_Z after the location errors and its head axis' map has no rotations.
  CHECK_NOTHROW(make_rtest_joint_model(MachineType::AC_trt, b, p, C, obs));
  const MachineType head = parse_machine_type("B-head-C-table");
  CHECK_THROWS_WITH(make_rtest_joint_model(head, b, p, C, obs), Catch::Contains("tool_offset_Z"));
  {
    const RtestBasis bh = b.for_machine(head);
    CHECK(!bh.b_rotations);  // B is on the head
    CHECK(bh.c_rotations);   // C is on the table
    const Eigen::Index nh = 9 + bh.num_b_coefficients() + bh.num_c_coefficients();
    CHECK(nh == n + 1 - 9);  // 9 odd-power rotation coefficients of the B map are not there
    const RtestJointModel mh =
        make_rtest_joint_model(head, b, Eigen::VectorXd::Zero(nh), Eigen::MatrixXd::Zero(nh, nh),
                               std::vector<bool>(static_cast<std::size_t>(nh), true));
    CHECK(mh.parameter_names().size() == static_cast<std::size_t>(nh));
    CHECK(mh.parameter_names()[8] == "tool_offset_Z");
    CHECK(mh.parameter_names()[9] == "dx_BZ.b2");
  }
  CHECK_THROWS_AS(make_rtest_joint_model(MachineType::BC_trt, b, p.head(n - 1), C, obs),
                  InvalidArgument);
  CHECK_THROWS_AS(make_rtest_joint_model(MachineType::BC_trt, b, p, C.topLeftCorner(n - 1, n), obs),
                  InvalidArgument);
  CHECK_THROWS_AS(make_rtest_joint_model(MachineType::BC_trt, b, p, C, {true}), InvalidArgument);
  Eigen::VectorXd bad = p;
  bad[9] = std::nan("");
  CHECK_THROWS_WITH(make_rtest_joint_model(MachineType::BC_trt, b, bad, C, obs),
                    Catch::Contains(b.coefficient_names()[1]));
}

TEST_CASE("held-out C = 15, 45, ... predicted from a fit on C = 0, 30, ...") {
  RtestSimOptions o;
  o.seed = 31;
  o.pattern.c_deg.clear();
  for (int j = 0; j < 24; ++j) o.pattern.c_deg.push_back(15.0 * j);
  const MachineModel t = truth();
  const RtestSimulation sim = simulate_rtest(t, o);
  const RtestSession fit = rows_where(sim.session, true), held = rows_where(sim.session, false);
  REQUIRE(fit.samples.size() == 168);
  REQUIRE(held.samples.size() == 168);
  const RtestJointIdentification id = identify_joint(fit);
  REQUIRE(id.converged);
  REQUIRE(id.unobservable.empty());

  const RtestSession pred = predict_session(id.model, held, id.probe_zeros);
  REQUIRE(pred.samples.size() == held.samples.size());
  REQUIRE(pred.extra_columns == rtest_prediction_std_columns());
  // Against the noise-free truth (reading + the set-up's true probe zero): the error is the
  // model's own estimation error, ~ noise * sqrt(p / n) = 0.3 * sqrt(70 / 504) ~ 0.11 um, and
  // its reported 1-sigma must account for it (RMS of the normalised errors below 2).
  double ss = 0.0, zz = 0.0;
  for (std::size_t i = 0; i < held.samples.size(); ++i) {
    const RtestSample& h = held.samples[i];
    const std::size_t nest = static_cast<std::size_t>(std::stoi(h.setup) - 1);
    const Eigen::Vector3d d_true =
        rtest_reading(t, held.nests.at(h.setup), h.angles_rad(), h.time) + sim.probe_zeros[nest];
    const Eigen::Vector3d err = *pred.samples[i].d - d_true;
    ss += err.squaredNorm();
    for (int k = 0; k < 3; ++k) {
      const double sd = std::stod(pred.samples[i].extra[static_cast<std::size_t>(k)]);
      CHECK(sd > 0.0);
      // Probe-zero uncertainty is not in the column: it adds ~ noise / sqrt(84) in quadrature.
      const double s_tot = std::hypot(sd, o.noise_um * 1e-3 / std::sqrt(84.0));
      zz += (err[k] / s_tot) * (err[k] / s_tot);
    }
  }
  const double n = 3.0 * static_cast<double>(held.samples.size());
  const double rms_um = std::sqrt(ss / n) * 1e3, z_rms = std::sqrt(zz / n);
  std::cout << "held-out prediction vs noise-free truth: RMS " << rms_um << " um (noise 0.3), "
            << "normalised RMS " << z_rms << "\n";
  CHECK(rms_um < 0.5 * o.noise_um);
  CHECK(z_rms < 2.0);
  CHECK(z_rms > 0.3);  // and does not overstate it wildly

  // Without probe zeros the prediction differs from the one with them by the zeros exactly.
  const RtestSession bare = predict_session(id.model, held);
  CHECK(
      (*bare.samples[0].d + id.probe_zeros.at(held.samples[0].setup) - *pred.samples[0].d).norm() <
      1e-15);
  // Raw readings are dropped, the file round-trips with the std columns and the note.
  std::istringstream in(format_rtest(pred));
  const RtestSession back = parse_rtest(in, "pred.csv");
  CHECK(back.extra_columns == rtest_prediction_std_columns());
  CHECK(back.samples[5].extra == pred.samples[5].extra);
  CHECK(format_rtest(back).find("# prediction: dx,dy,dz predicted") != std::string::npos);
  CHECK_THROWS_AS(predict_session(id.model, held, {{"1", Eigen::Vector3d::Zero()}}),
                  InvalidArgument);
}
