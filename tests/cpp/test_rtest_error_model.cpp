// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/error_model.hpp: Oyama Eqs. 4-9 and the mapping to ISO 230-7 location errors.
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <random>

#include "rotacal/rtest/error_model.hpp"

using namespace rotacal;

namespace {
constexpr double kDeg = M_PI / 180.0;
AxisErrors<double> random_w(std::mt19937& rng, double t_mm, double r_rad) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  AxisErrors<double> w;
  for (int k = 0; k < 6; ++k) w[k] = U(rng) * (k < 3 ? t_mm : r_rad);
  return w;
}
LocationErrors<double> truth_errors() {  // ../shared/data/rtest_bc_oyama.truth.json
  Eigen::Matrix<double, 8, 1> v;
  v << 0.01459190348066346, 0.014212100597282357, 3.1102339878434216e-05, -2.385536385835234e-05,
      -0.016912021691263143, 0.017858631217842532, 1.1379169104710182e-05, -4.973692463737003e-05;
  return LocationErrors<double>(v);
}
}  // namespace

TEST_CASE("error factor is the product of the D matrices of Eq. 1 and round-trips") {
  std::mt19937 rng(1);
  const AxisErrors<double> w = random_w(rng, 0.02, 0.3);  // large angles: exact, not small
  CHECK((oyama_error_pose(w).matrix() - oyama_error_htm(w)).norm() < 1e-14);
  CHECK((oyama_errors_of(oyama_error_pose(w)) - w).norm() < 1e-14);
  // Eqs. 5-7 as literal HTM products.
  const AxisErrors<double> v = random_w(rng, 0.02, 0.3);
  const double B = 0.7, C = -2.1;
  const Mat4<double> T = oyama_error_htm(w) * D_b<double>(B) * oyama_error_htm(v) * D_c<double>(C);
  CHECK((oyama_table_pose<double>(w, v, B, C).matrix() - T).norm() < 1e-14);
}

TEST_CASE("exact Eq. 4 and small-angle Eqs. 8-9 agree to second order") {
  std::mt19937 rng(2);
  const Eigen::Vector3d p(100.0, -40.0, 60.0);
  for (int trial = 0; trial < 20; ++trial) {
    const AxisErrors<double> w = random_w(rng, 0.02, 1e-4), v = random_w(rng, 0.02, 1e-4);
    const double B = (trial % 7 - 3) * 30.0 * kDeg, C = trial * 30.0 * kDeg;
    double diff[2];
    for (int s = 0; s < 2; ++s) {
      const double lam = s == 0 ? 1.0 : 2.0;
      const AxisErrors<double> ws = lam * w, vs = lam * v;
      diff[s] = (oyama_displacement<double>(ws, vs, B, C, p) -
                 oyama_small_angle_displacement<double>(ws, vs, B, C, p))
                    .norm();
    }
    // First-order terms are ~ 20 um; the remainder is second order: doubling the errors
    // multiplies it by 4 (to within the third-order part).
    CHECK(diff[0] < 2e-5);  // second order: eps^2 |p| + eps delta ~ 1e-8 * 130 mm + 4e-9
    CHECK(diff[1] / diff[0] == Approx(4.0).epsilon(0.05));
  }
}

TEST_CASE("sign of the small-angle form: a table shifted +z makes the sphere read -z") {
  AxisErrors<double> w = AxisErrors<double>::Zero();
  w[2] = 0.01;  // dz_BY: table up by 10 um at B = 0
  const Eigen::Vector3d d = oyama_displacement<double>(w, AxisErrors<double>::Zero(), 0.0, 0.0,
                                                       Eigen::Vector3d(50, 0, 0));
  CHECK((d - Eigen::Vector3d(0, 0, -0.01)).norm() < 1e-15);
  CHECK(oyama_small_angle_twist<double>(w, AxisErrors<double>::Zero(), 0.0, 0.0)[2] == 0.01);
}

TEST_CASE("constant Oyama errors reproduce the location-error kinematics up to a table-frame F") {
  const LocationErrors<double> e = truth_errors();
  const OyamaConstantErrors m = oyama_from_location(e);
  for (int i = -3; i <= 3; ++i)
    for (int j = 0; j < 12; ++j) {
      const double B = i * 30.0 * kDeg, C = j * 30.0 * kDeg;
      const Pose<double> T_loc = table_pose<double>(MachineType::BC_trt, e, {B, C});
      const Pose<double> T_oy = oyama_table_pose<double>(m.w_BY, m.w_CB, B, C) * m.F;
      CHECK((T_loc.matrix() - T_oy.matrix()).norm() < 1e-12);
      // And the joint-fit model with w = 0 is machine.hpp's table_pose.
      const Pose<double> T_j =
          rtest_table_pose<double>(e, AxisErrors<double>::Zero(), AxisErrors<double>::Zero(), B, C);
      CHECK((T_loc.matrix() - T_j.matrix()).norm() < 1e-14);
    }
  // R-test readings: d_loc = F^-1 (q + d_oy) - q, i.e. d_oy plus a constant per nest, up to
  // F's 50 urad rotation of the ~30 um readings (~2 nm).
  const Eigen::Vector3d q(100.0, 0.0, 60.0);
  const AxisErrors<double> z = AxisErrors<double>::Zero();
  const Eigen::Vector3d shift = m.F.inverse() * q - q;
  for (int i = -3; i <= 3; ++i) {
    const double B = i * 30.0 * kDeg, C = i * 50.0 * kDeg;
    const Eigen::Vector3d p = oyama_table_pose<double>(z, z, B, C) * q;
    const Eigen::Vector3d d_loc =
        table_pose<double>(MachineType::BC_trt, e, {B, C}).inverse() * p - q;
    const Eigen::Vector3d d_oy = oyama_displacement<double>(m.w_BY, m.w_CB, B, C, q);
    CHECK((d_loc - (m.F.inverse() * (q + d_oy) - q)).norm() < 1e-12);
    CHECK((d_loc - (d_oy + shift)).norm() < 5e-6);
  }
}

TEST_CASE("first-order location mapping equals the exact one to second order") {
  const LocationErrors<double> e0 = truth_errors();
  double diff[2];
  for (int s = 0; s < 2; ++s) {
    const LocationErrors<double> e(e0.v * (s == 0 ? 1.0 : 2.0));
    const OyamaConstantErrors a = oyama_from_location(e), b = oyama_from_location_first_order(e);
    diff[s] = (a.w_BY - b.w_BY).norm() + (a.w_CB - b.w_CB).norm();
  }
  CHECK(diff[0] < 5e-6);  // products of ~30 um and ~50 urad: ~1e-6
  CHECK(diff[1] / diff[0] == Approx(4.0).epsilon(0.05));
}

TEST_CASE("the Oyama model is templated: Jets flow and match finite differences") {
  using J = ceres::Jet<double, 6>;
  AxisErrors<J> w;
  for (int k = 0; k < 6; ++k) w[k] = J(0.001 * (k + 1), k);
  const AxisErrors<J> v = AxisErrors<J>::Zero();
  const Vec3<J> p(J(100.0), J(-20.0), J(60.0));
  const Vec3<J> d = oyama_displacement<J>(w, v, J(0.5), J(1.2), p);
  AxisErrors<double> wd;
  for (int k = 0; k < 6; ++k) wd[k] = 0.001 * (k + 1);
  for (int k = 0; k < 6; ++k) {
    const double h = 1e-7;
    AxisErrors<double> wp = wd, wm = wd;
    wp[k] += h;
    wm[k] -= h;
    const AxisErrors<double> vz = AxisErrors<double>::Zero();
    const Eigen::Vector3d fd =
        (oyama_displacement<double>(wp, vz, 0.5, 1.2, Eigen::Vector3d(100.0, -20.0, 60.0)) -
         oyama_displacement<double>(wm, vz, 0.5, 1.2, Eigen::Vector3d(100.0, -20.0, 60.0))) /
        (2 * h);
    for (int r = 0; r < 3; ++r) CHECK(d[r].v[k] == Approx(fd[r]).margin(1e-6));
  }
}
