// SPDX-License-Identifier: BSD-3-Clause
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <random>

#include "rotacal/kinematics/rotation.hpp"

using namespace rotacal;
using Catch::Matchers::WithinAbs;

TEST_CASE("rotation_about_line matches Flynn Eq. 1 written out", "[rotation]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d a(100 * U(rng), 100 * U(rng), 100 * U(rng));
    const Eigen::Vector3d d = Eigen::Vector3d(U(rng), U(rng), U(rng)).normalized();
    const Eigen::Vector3d q(200 * U(rng), 200 * U(rng), 200 * U(rng));
    const double th = 3.0 * U(rng);
    const Eigen::Vector3d p1 = rotation_about_line<double>(a, d, th) * q;
    const Eigen::Vector3d p2 = flynn_eq1<double>(q, a, d, th);
    CHECK((p1 - p2).norm() < 1e-10);
  }
}

TEST_CASE("rotation_about_line: points on the line stay, distances are kept", "[rotation]") {
  const Eigen::Vector3d a(1, 2, 3), d(0.3, -0.2, 1.0);
  const Pose<double> T = rotation_about_line<double>(a, d, 0.7);
  CHECK((T * (a + 5.0 * d) - (a + 5.0 * d)).norm() < 1e-12);
  const Eigen::Vector3d p(10, -4, 2), q(-3, 8, 1);
  CHECK_THAT((T * p - T * q).norm(), WithinAbs((p - q).norm(), 1e-12));
  CHECK((T.R.transpose() * T.R - Eigen::Matrix3d::Identity()).norm() < 1e-14);
  CHECK_THAT(T.R.determinant(), WithinAbs(1.0, 1e-14));
  // Right-handed: +90 deg about +Z takes +X to +Y.
  const Pose<double> Rz =
      rotation_about_line<double>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), M_PI / 2);
  CHECK((Rz * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm() < 1e-15);
}

TEST_CASE("Pose composition and inverse round-trip", "[rotation]") {
  const Pose<double> A = rotation_about_line<double>({1, 0, 2}, {0, 1, 0.1}, 0.4);
  const Pose<double> B = rotation_about_line<double>({-3, 1, 0}, {0.2, 0, 1}, -1.1);
  const Eigen::Vector3d p(5, 6, 7);
  CHECK(((A * B) * p - A * (B * p)).norm() < 1e-12);
  CHECK(((A.inverse() * A) * p - p).norm() < 1e-12);
  CHECK(((A * B).matrix() - A.matrix() * B.matrix()).norm() < 1e-12);
}

TEST_CASE("HTMs D_a, D_b, D_c are the Oyama Eq. 1 matrices", "[rotation]") {
  const double t = 0.3, c = std::cos(t), s = std::sin(t);
  Eigen::Matrix4d Da, Db, Dc;
  Da << 1, 0, 0, 0, 0, c, -s, 0, 0, s, c, 0, 0, 0, 0, 1;
  Db << c, 0, s, 0, 0, 1, 0, 0, -s, 0, c, 0, 0, 0, 0, 1;
  Dc << c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  CHECK((D_a(t) - Da).norm() < 1e-15);
  CHECK((D_b(t) - Db).norm() < 1e-15);
  CHECK((D_c(t) - Dc).norm() < 1e-15);
  CHECK((D_x(2.0) * D_y(3.0) * D_z(4.0)).col(3).head<3>().isApprox(Eigen::Vector3d(2, 3, 4)));
}

TEST_CASE("rotation_about_line is differentiable with ceres::Jet", "[rotation][jet]") {
  using J = ceres::Jet<double, 1>;
  // d/dtheta of the rotated point = u x (q - a); check against that closed form.
  const Eigen::Vector3d a(1, -2, 0.5), d(0.1, 0.2, 1.0), q(10, 3, -4);
  const double th = 0.9;
  const Vec3<J> aj = a.cast<J>(), dj = d.cast<J>(), qj = q.cast<J>();
  const Vec3<J> p = rotation_about_line<J>(aj, dj, J(th, 0)) * qj;
  const Eigen::Vector3d u = d.normalized();
  const Eigen::Vector3d expected = u.cross(rotation_about_line<double>(a, d, th) * q - a);
  for (int i = 0; i < 3; ++i) CHECK_THAT(p[i].v[0], WithinAbs(expected[i], 1e-10));
}

TEST_CASE("rotate_point_about_line is the Pose form applied to a point", "[rotation]") {
  const Eigen::Vector3d a(3, -1, 2), d(0.2, 1.0, -0.3), q(40, 5, -7);
  for (double th : {-2.0, 0.0, 0.3, 3.0}) {
    CHECK((rotate_point_about_line<double>(a, d, th, q) - rotation_about_line<double>(a, d, th) * q)
              .norm() < 1e-12);
  }
}

TEST_CASE("rotate_point_about_line_derivatives agree with Jets of rotate_point_about_line",
          "[rotation][jet]") {
  using J = ceres::Jet<double, 9>;
  std::mt19937 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d a(N(rng), N(rng), N(rng)), d(N(rng), N(rng), N(rng)),
        q(100 * N(rng), 100 * N(rng), 100 * N(rng));
    const double theta = 3.0 * N(rng);
    Vec3<J> aj, dj, qj;
    for (int k = 0; k < 3; ++k) aj[k] = J(a[k], k), dj[k] = J(d[k], 3 + k), qj[k] = J(q[k], 6 + k);
    const Vec3<J> f = rotate_point_about_line<J>(aj, dj, J(theta), qj);
    const LineRotationDerivatives<double> D = rotate_point_about_line_derivatives(a, d, theta, q);
    for (int r = 0; r < 3; ++r) {
      CHECK(std::abs(D.f[r] - f[r].a) < 1e-12 * (1 + std::abs(f[r].a)));
      for (int k = 0; k < 3; ++k) {
        CHECK(std::abs(D.d_point()(r, k) - f[r].v[k]) < 1e-10);
        CHECK(std::abs(D.d_direction()(r, k) - f[r].v[3 + k]) < 1e-9 * (1 + q.norm()));
        CHECK(std::abs(D.d_q()(r, k) - f[r].v[6 + k]) < 1e-12);
      }
    }
  }
}
