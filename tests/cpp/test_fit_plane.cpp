// SPDX-License-Identifier: BSD-3-Clause
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <limits>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/fit/plane.hpp"

using namespace rotacal;

TEST_CASE("SVD plane fit recovers a tilted plane and its normal's uncertainty", "[fit]") {
  std::mt19937 rng(1);
  const Eigen::Vector3d n =
      Eigen::Vector3d(2e-5, -4e-5, 1.0).normalized();  // a tilted axial-test plane
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  const double sigma = 0.5e-3;
  std::normal_distribution<double> N(0.0, sigma);
  const int draws = 300;
  Eigen::Vector2d sq = Eigen::Vector2d::Zero(), rep = Eigen::Vector2d::Zero();
  for (int k = 0; k < draws; ++k) {
    Points3 p(360, 3);
    for (int i = 0; i < 360; ++i) {
      const double t = i * M_PI / 180;
      p.row(i) =
          (Eigen::Vector3d(0, 0, 160) + 120 * std::cos(t) * u + 120 * std::sin(t) * v + N(rng) * n)
              .transpose();
    }
    const PlaneFit f = svd_plane_fit(p);
    CHECK(f.normal.z() > 0);
    const Eigen::Vector3d d = f.normal - n;
    sq += Eigen::Vector2d(std::pow(d.dot(u), 2), std::pow(d.dot(v), 2));
    rep += Eigen::Vector2d(std::sqrt(u.dot(f.normal_covariance * u)),
                           std::sqrt(v.dot(f.normal_covariance * v)));
    CHECK(std::abs(n.dot(f.normal_covariance * n)) <
          1e-20);  // rank 2: no variance along the normal
  }
  for (int j = 0; j < 2; ++j)
    CHECK(std::sqrt(sq[j] / draws) == Approx(rep[j] / draws).epsilon(0.15));
}

TEST_CASE("plane fit: sign from the hint, degenerate input refused", "[fit]") {
  Points3 p(4, 3);
  p << 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1;
  CHECK(svd_plane_fit(p).normal.isApprox(Eigen::Vector3d::UnitZ()));
  CHECK(svd_plane_fit(p, -Eigen::Vector3d::UnitZ()).normal.isApprox(-Eigen::Vector3d::UnitZ()));
  CHECK(svd_plane_fit(p).centroid.isApprox(Eigen::Vector3d(0.5, 0.5, 1)));
  Points3 line(4, 3);
  line << 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3;
  CHECK_THROWS_WITH(svd_plane_fit(line), Catch::Contains("collinear"));
  CHECK_THROWS_AS(svd_plane_fit(p.topRows(2)), DegenerateGeometry);
  CHECK_THROWS_AS(svd_plane_fit(p, Eigen::Vector3d::Zero()), InvalidArgument);
  CHECK_THROWS_WITH(
      svd_plane_fit(line, Eigen::Vector3d::UnitZ(), 0.0, "s.csv: test axial_C"),
      Catch::StartsWith("s.csv: test axial_C: svd_plane_fit: the 4 points are collinear"));
  Points3 nan = p;
  nan(2, 0) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(svd_plane_fit(nan), Catch::Contains("point 2 of 4"));
}
