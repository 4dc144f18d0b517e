// SPDX-License-Identifier: BSD-3-Clause
// The two solvers of the circle and sphere fits' geometric refinement: rotacal's joint-fit
// driver (every build; the only one with -DROTACAL_CERES_SOLVER=OFF) recovers known shapes from
// noisy points, and where the library has Ceres' solver too, both reach the same minimum.
#include <Eigen/LU>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "../../src/fit/orthogonal_distance.hpp"
#include "rotacal/core/error.hpp"

using namespace rotacal;

namespace {

// n points on an arc of `span` rad around c (radius R), noise sigma along the radius (a
// ballbar's or a probe's reading); Dim 3: on a band of the sphere, +-60 deg of latitude.
template <int Dim>
PointRows<Dim> arc(const Eigen::Matrix<double, Dim, 1>& c, double R, double span, int n,
                   double sigma, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, sigma);
  PointRows<Dim> p(n, Dim);
  for (int i = 0; i < n; ++i) {
    const double t = span * i / (n - 1);
    Eigen::Matrix<double, Dim, 1> u;
    if constexpr (Dim == 2) {
      u << std::cos(t), std::sin(t);
    } else {
      const double lat = (2.0 * (i % 7) / 6.0 - 1.0) * M_PI / 3.0;
      u << std::cos(lat) * std::cos(t), std::cos(lat) * std::sin(t), std::sin(lat);
    }
    p.row(i) = (c + (R + N(rng)) * u).transpose();
  }
  return p;
}

// The start the fits give the refinement: near the solution, not on it.
template <int Dim>
void start_near(const Eigen::Matrix<double, Dim, 1>& c, double R, Eigen::Matrix<double, Dim, 1>& c0,
                double& R0) {
  c0 = c + Eigen::Matrix<double, Dim, 1>::Constant(0.05);
  R0 = R - 0.03;
}

// 1 sigma of (centre, radius) at the solution c for points with independent noise `noise`
// along the radius: sqrt(diag((J^T J)^-1)) noise, J the residuals' Jacobian (radius held: no
// radius column, its sigma 0).
template <int Dim>
Eigen::VectorXd sigmas(const PointRows<Dim>& p, const Eigen::Matrix<double, Dim, 1>& c, bool fix,
                       double noise) {
  const int k = fix ? Dim : Dim + 1;
  Eigen::MatrixXd J(p.rows(), k);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    J.row(i).head(Dim) = -(p.row(i).transpose() - c).normalized().transpose();
    if (!fix) J(i, Dim) = -1.0;
  }
  Eigen::VectorXd s = Eigen::VectorXd::Zero(Dim + 1);
  s.head(k) = (J.transpose() * J).inverse().diagonal().cwiseSqrt() * noise;
  return s;
}

// The largest difference of two solutions (centre, radius) in units of their 1 sigma.
template <int Dim>
double in_sigmas(const Eigen::Matrix<double, Dim, 1>& ca, double ra,
                 const Eigen::Matrix<double, Dim, 1>& cb, double rb, const Eigen::VectorXd& s) {
  double m = 0.0;
  for (int k = 0; k < Dim; ++k) m = std::max(m, std::abs(ca[k] - cb[k]) / s[k]);
  return s[Dim] > 0.0 ? std::max(m, std::abs(ra - rb) / s[Dim]) : m;
}

}  // namespace

TEST_CASE("the joint-fit driver recovers a circle and a sphere from noisy points", "[fit]") {
  std::mt19937 rng(52);
  const double sigma = 1e-3, R = 100.0;  // mm: 1 um of noise on a 100 mm ballbar
  const int n = 400;
  // Within 5 sigma of the truth, for each parameter: a failure is not noise.
  const Eigen::Vector2d c2(120.0, -40.0);
  const PointRows<2> circle = arc<2>(c2, R, 2 * M_PI * (n - 1) / n, n, sigma, rng);
  Eigen::Vector2d centre2;
  double radius2;
  start_near<2>(c2, R, centre2, radius2);
  CHECK(refine_orthogonal_distance<2>(circle, centre2, radius2, false, DistanceSolver::joint));
  CHECK(in_sigmas<2>(centre2, radius2, c2, R, sigmas<2>(circle, c2, false, sigma)) < 5.0);

  const Eigen::Vector3d c3(120.0, -40.0, 60.0);
  const PointRows<3> sphere = arc<3>(c3, R, 2 * M_PI * (n - 1) / n, n, sigma, rng);
  Eigen::Vector3d centre3;
  double radius3;
  start_near<3>(c3, R, centre3, radius3);
  CHECK(refine_orthogonal_distance<3>(sphere, centre3, radius3, false, DistanceSolver::joint));
  CHECK(in_sigmas<3>(centre3, radius3, c3, R, sigmas<3>(sphere, c3, false, sigma)) < 5.0);

  // A held radius stays where it was put.
  start_near<3>(c3, R, centre3, radius3);
  radius3 = R;
  CHECK(refine_orthogonal_distance<3>(sphere, centre3, radius3, true, DistanceSolver::joint));
  CHECK(radius3 == R);
  CHECK(in_sigmas<3>(centre3, radius3, c3, R, sigmas<3>(sphere, c3, true, sigma)) < 5.0);
}

TEST_CASE("Ceres' solver and the joint-fit driver reach the same minimum", "[fit]") {
  std::mt19937 rng(53);
  const double sigma = 1e-3, R = 100.0;
  const int n = 300;
  const Eigen::Vector2d c2(5.0, 7.0);
  const Eigen::Vector3d c3(5.0, 7.0, -3.0);
  if (!ceres_solver_built()) {
    // -DROTACAL_CERES_SOLVER=OFF: asking for Ceres' solver is an error, not a silent fallback.
    const PointRows<2> p = arc<2>(c2, R, M_PI, n, sigma, rng);
    Eigen::Vector2d c = c2;
    double r = R;
    CHECK_THROWS_AS(refine_orthogonal_distance<2>(p, c, r, false, DistanceSolver::ceres),
                    InvalidArgument);
    return;
  }
  // Arcs of 360, 90 and 30 degrees: on the short ones centre and radius are strongly correlated
  // and the minimum is flat, where two solvers that stop early would part first. Both stop at
  // the minimum to round-off (Ceres: relative cost change 1e-15; the driver: step below 1e-8
  // sigma on a Jacobian at the solution): they must agree to 1e-4 of each parameter's sigma.
  for (const double span_deg : {360.0, 90.0, 30.0}) {
    INFO("arc of " << span_deg << " deg");
    const double span = span_deg * M_PI / 180.0 * (span_deg == 360.0 ? (n - 1.0) / n : 1.0);
    const PointRows<2> p2 = arc<2>(c2, R, span, n, sigma, rng);
    Eigen::Vector2d a, b;
    double ra, rb;
    start_near<2>(c2, R, a, ra);
    start_near<2>(c2, R, b, rb);
    CHECK(refine_orthogonal_distance<2>(p2, a, ra, false, DistanceSolver::ceres));
    CHECK(refine_orthogonal_distance<2>(p2, b, rb, false, DistanceSolver::joint));
    CHECK(in_sigmas<2>(a, ra, b, rb, sigmas<2>(p2, a, false, sigma)) < 1e-4);

    const PointRows<3> p3 = arc<3>(c3, R, span, n, sigma, rng);
    for (const bool fix : {false, true}) {
      INFO("sphere, radius " << (fix ? "held at the true one" : "free"));
      Eigen::Vector3d a3, b3;
      double ra3, rb3;
      start_near<3>(c3, R, a3, ra3);
      start_near<3>(c3, R, b3, rb3);
      if (fix) ra3 = rb3 = R;  // as the ballbar's calibrated length is held
      CHECK(refine_orthogonal_distance<3>(p3, a3, ra3, fix, DistanceSolver::ceres));
      CHECK(refine_orthogonal_distance<3>(p3, b3, rb3, fix, DistanceSolver::joint));
      CHECK(in_sigmas<3>(a3, ra3, b3, rb3, sigmas<3>(p3, a3, fix, sigma)) < 1e-4);
    }
  }
}
