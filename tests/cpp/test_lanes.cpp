// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "rotacal/core/lanes.hpp"
#include "rotacal/kinematics/rotation.hpp"

using namespace rotacal;

namespace {

Lanes lanes_of(const double (&x)[Lanes::kSize]) {
  Lanes out;
  for (int l = 0; l < Lanes::kSize; ++l) out[l] = x[l];
  return out;
}

Vec3<Lanes> lanes_of(const Eigen::Vector3d (&x)[Lanes::kSize]) {
  Vec3<Lanes> out;
  for (int a = 0; a < 3; ++a)
    for (int l = 0; l < Lanes::kSize; ++l) out[a][l] = x[l][a];
  return out;
}

}  // namespace

TEST_CASE("Lanes: each lane does its own arithmetic, constants reach every lane", "[lanes]") {
  const Lanes a = lanes_of({1.0, -2.0, 3.5, 0.25}), b = lanes_of({4.0, 0.5, -1.0, 8.0});
  const Lanes sum = a + b, diff = a - b, prod = a * b, quot = a / b, neg = -a, root = sqrt(b * b);
  const Lanes mixed = 2.0 - a;  // a double on the left becomes a constant in every lane
  for (int l = 0; l < Lanes::kSize; ++l) {
    CHECK(sum[l] == a[l] + b[l]);
    CHECK(diff[l] == a[l] - b[l]);
    CHECK(prod[l] == a[l] * b[l]);
    CHECK(quot[l] == a[l] / b[l]);
    CHECK(neg[l] == -a[l]);
    CHECK(root[l] == std::abs(b[l]));
    CHECK(mixed[l] == 2.0 - a[l]);
  }
  Lanes acc = a;
  acc += b;
  acc *= b;
  acc -= a;
  acc /= b;
  for (int l = 0; l < Lanes::kSize; ++l) CHECK(acc[l] == ((a[l] + b[l]) * b[l] - a[l]) / b[l]);
}

TEST_CASE("Lanes through Eigen: norms, cross and dot products lane by lane", "[lanes]") {
  const Eigen::Vector3d u[4] = {{1, 2, 3}, {-0.5, 4, 2}, {0, 0, 1}, {7, -1, 0.25}};
  const Eigen::Vector3d v[4] = {{3, -1, 2}, {1, 1, 1}, {2, 5, -3}, {0.1, 0.2, 0.3}};
  const Vec3<Lanes> U = lanes_of(u), V = lanes_of(v);
  const Vec3<Lanes> c = U.cross(V);
  const Lanes d = U.dot(V), n = U.norm();
  for (int l = 0; l < Lanes::kSize; ++l) {
    const Eigen::Vector3d cl = u[l].cross(v[l]);
    for (int a = 0; a < 3; ++a) CHECK(std::abs(c[a][l] - cl[a]) < 1e-14);
    CHECK(std::abs(d[l] - u[l].dot(v[l])) < 1e-13);
    CHECK(std::abs(n[l] - u[l].norm()) < 1e-14);
  }
}

TEST_CASE("the rotation and its derivative products in Lanes equal four double evaluations",
          "[lanes][rotation]") {
  std::mt19937 rng(11);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int trial = 0; trial < 25; ++trial) {
    // One line (as in a fit: the axis line is the same for every sample), four samples.
    const Eigen::Vector3d point(N(rng), N(rng), N(rng)), d(N(rng), N(rng), 1.0 + 0.1 * N(rng));
    const double inv_norm = 1.0 / d.norm();
    const Eigen::Vector3d u = d * inv_norm;
    Eigen::Vector3d q[4], w3[4];
    double c[4], s[4];
    for (int l = 0; l < 4; ++l) {
      q[l] = Eigen::Vector3d(100 * N(rng), 100 * N(rng), 100 * N(rng));
      w3[l] = Eigen::Vector3d(N(rng), N(rng), N(rng));
      const double th = 3.0 * N(rng);
      c[l] = std::cos(th), s[l] = std::sin(th);
    }
    const LineRotationDerivatives<Lanes> D = rotate_point_about_unit_line_derivatives<Lanes>(
        point.cast<Lanes>(), u.cast<Lanes>(), Lanes(inv_norm), lanes_of(c), lanes_of(s),
        lanes_of(q));
    const Eigen::Matrix<Lanes, 1, 3> W = lanes_of(w3).transpose();
    const Eigen::Matrix<Lanes, 1, 3> wq = D.times_q(W), wu = D.times_unit_direction(W),
                                     wd = D.times_direction(W);
    for (int l = 0; l < 4; ++l) {
      const LineRotationDerivatives<double> Dl =
          rotate_point_about_unit_line_derivatives<double>(point, u, inv_norm, c[l], s[l], q[l]);
      const Eigen::RowVector3d w = w3[l].transpose();
      const Eigen::RowVector3d eq = Dl.times_q(w), eu = Dl.times_unit_direction(w),
                               ed = Dl.times_direction(w);
      for (int a = 0; a < 3; ++a) {
        CHECK(std::abs(D.f[a][l] - Dl.f[a]) < 1e-12 * (1.0 + std::abs(Dl.f[a])));
        CHECK(std::abs(wq[a][l] - eq[a]) < 1e-12);
        CHECK(std::abs(wu[a][l] - eu[a]) < 1e-10 * (1.0 + q[l].norm()));
        CHECK(std::abs(wd[a][l] - ed[a]) < 1e-10 * (1.0 + q[l].norm()));
      }
    }
  }
}
