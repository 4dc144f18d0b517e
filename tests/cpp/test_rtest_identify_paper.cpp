// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/identify_paper.hpp: the paper's two-step method on simulated sessions whose
// position-dependent errors are known in closed form.
#include <catch2/catch.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/rtest/identify_paper.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
constexpr double kDeg = M_PI / 180.0;
const double s_sag = 0.006, k_con = 1.45e-4;       // gravity sag (mm), coning (rad/rad)
const double ax = 0.002, tx = 20e-6, ty = -15e-6;  // C: axial sin 2C (mm), tilt sin 2C (rad)

MachineModel truth_b_and_c() {
  MachineModel t = MachineModel::nominal(MachineType::BC_trt);
  t.effects.effects = {Effect::parse("gravity_sag_B"), Effect::parse("coning_B"),
                       Effect::parse("axial_motion_C_h2"), Effect::parse("tilt_motion_C_h2")};
  // axial: a cos + b sin; tilt: (a cos + b sin) about X, (c cos + d sin) about Y (turning frame)
  t.effect_params = {s_sag, k_con, 0.0, ax, 0.0, tx, 0.0, ty};
  return t;
}
// Closed-form truth in Oyama form: w_BY = (0,0,-s(1-cos B), k B, 0, 0); w_CB = the turning-frame
// motion seen in the B-axis frame: dz = ax sin 2C, (alpha, beta) = Rz(C) (tx, ty) sin 2C.
AxisErrors<double> w_by_truth(double B) {
  AxisErrors<double> w = AxisErrors<double>::Zero();
  w[2] = -s_sag * (1 - std::cos(B));
  w[3] = k_con * B;
  return w;
}
AxisErrors<double> w_cb_truth(double C) {
  AxisErrors<double> w = AxisErrors<double>::Zero();
  w[2] = ax * std::sin(2 * C);
  w[3] = std::sin(2 * C) * (std::cos(C) * tx - std::sin(C) * ty);
  w[4] = std::sin(2 * C) * (std::sin(C) * tx + std::cos(C) * ty);
  return w;
}
}  // namespace

TEST_CASE("paper method recovers B and C maps from noise-free readings") {
  RtestSimOptions o;
  o.noise_um = 0.0;
  const RtestSimulation sim = simulate_rtest(truth_b_and_c(), o);
  const RtestPaperIdentification id = identify_paper(sim.session);
  REQUIRE(id.b_deg.size() == 7);
  REQUIRE(id.c_deg.size() == 12);
  for (std::size_t i = 0; i < 7; ++i) {
    const AxisErrors<double> w = w_by_truth(id.b_deg[i] * kDeg);
    // Second-order model error of Eqs. 8-9: ~ eps^2 |q| + eps * delta < 10 nm.
    CHECK((id.w_BY[i].head<3>() - w.head<3>()).norm() < 1e-5);
    CHECK((id.w_BY[i].tail<3>() - w.tail<3>()).norm() < 1e-7);
    for (std::size_t j = 0; j < 12; ++j) {
      const AxisErrors<double> v = w_cb_truth(id.c_deg[j] * kDeg);
      CHECK((id.w_CB[i][j].head<3>() - v.head<3>()).norm() < 1e-5);
      CHECK((id.w_CB[i][j].tail<3>() - v.tail<3>()).norm() < 1e-7);
    }
  }
  CHECK(id.residual_rms_um < 0.01);
  CHECK_FALSE(id.notes.empty());
  // dz_BY(0) and gamma_BY(0) cancel against the reference pose: reported, not fitted.
  CHECK_FALSE(id.unobservable.empty());
}

TEST_CASE("paper method with noise: errors within the reported uncertainty") {
  RtestSimOptions o;
  o.noise_um = 0.3;
  o.seed = 5;
  const RtestSimulation sim = simulate_rtest(truth_b_and_c(), o);
  const RtestPaperIdentification id = identify_paper(sim.session);
  int n = 0, within = 0;
  for (std::size_t i = 0; i < 7; ++i) {
    const AxisErrors<double> w = w_by_truth(id.b_deg[i] * kDeg);
    for (int k = 0; k < 6; ++k) {
      if (id.w_BY_std[i][k] == 0.0) continue;
      ++n;
      within += std::abs(id.w_BY[i][k] - w[k]) < 3.0 * id.w_BY_std[i][k];
      CHECK(std::abs(id.w_BY[i][k] - w[k]) < 5.0 * id.w_BY_std[i][k]);
    }
  }
  // The reference reading carries noise too, so errors are correlated across B_i; still, most
  // lie within 3 sigma.
  CHECK(within >= 0.85 * n);
  // Residual RMS: 2 nests x 3 readings - 5 unknowns = 1 dof per pose in step 2 -> ~0.3/sqrt(6).
  CHECK(id.residual_rms_um < 0.3);
}

TEST_CASE("paper method refuses sessions it cannot handle") {
  RtestSimOptions o;
  o.pattern.nests.resize(1);
  CHECK_THROWS_AS(identify_paper(simulate_rtest(truth_b_and_c(), o).session), InvalidArgument);
  RtestSimOptions o2;
  o2.pattern.b_deg = {-90, -60, -30, 30, 60, 90};  // no B = 0 reference
  CHECK_THROWS_AS(identify_paper(simulate_rtest(truth_b_and_c(), o2).session), InvalidArgument);
  RtestSimulation sim = simulate_rtest(truth_b_and_c(), RtestSimOptions{});
  sim.session.samples.pop_back();  // incomplete grid
  CHECK_THROWS_AS(identify_paper(sim.session), InvalidArgument);
}
