// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/fit/circle.hpp"

using namespace rotacal;

namespace {
Points2 arc(double cx, double cy, double r, double from, double to, int n, double sigma,
            std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, sigma);
  Points2 p(n, 2);
  for (int i = 0; i < n; ++i) {
    const double t = from + (to - from) * i / (n - 1);
    p.row(i) << cx + r * std::cos(t) + N(rng), cy + r * std::sin(t) + N(rng);
  }
  return p;
}
}  // namespace

TEST_CASE("Hyper and Kasa fits recover an exact circle", "[fit]") {
  std::mt19937 rng(1);
  const Points2 p = arc(3.0, -2.0, 60.0, 0.0, 2 * M_PI * 359 / 360, 360, 0.0, rng);
  for (const CircleFit& f : {hyper_circle_fit(p), kasa_circle_fit(p)}) {
    CHECK((f.centre - Eigen::Vector2d(3.0, -2.0)).norm() < 1e-9);
    CHECK(f.radius == Approx(60.0).epsilon(1e-12));
    CHECK(f.rms < 1e-9);
  }
}

TEST_CASE("reported 1-sigma uncertainties agree with Monte Carlo", "[fit]") {
  std::mt19937 rng(2);
  const double sigma = 0.5e-3;  // 0.5 um on a 120 mm circle, a half turn
  const int draws = 400;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
  Eigen::Vector3d reported = Eigen::Vector3d::Zero();
  for (int k = 0; k < draws; ++k) {
    const CircleFit f =
        hyper_circle_fit(arc(0.0, 60.0, 120.0, -M_PI / 2, M_PI / 2, 181, sigma, rng));
    const Eigen::Vector3d v(f.centre.x(), f.centre.y() - 60.0, f.radius - 120.0);
    sum += v;
    sq += v.cwiseProduct(v);
    reported += f.covariance.diagonal().cwiseSqrt();
  }
  const Eigen::Vector3d mean = sum / draws;
  const Eigen::Vector3d empirical = (sq / draws - mean.cwiseProduct(mean)).cwiseSqrt();
  reported /= draws;
  for (int j = 0; j < 3; ++j) {
    INFO("component " << j << ": empirical " << empirical[j] << ", reported " << reported[j]);
    CHECK(empirical[j] == Approx(reported[j]).epsilon(0.15));  // 400 draws: ~4 % scatter of a std
    CHECK(std::abs(mean[j]) < 4 * empirical[j] / std::sqrt(draws));  // unbiased
  }
}

TEST_CASE("on a short noisy arc Hyper is essentially unbiased and Kasa is not", "[fit]") {
  // 30 degree arc of radius 100 with 0.05 mm noise: Kasa's radius is biased low by several of
  // its own standard errors of the mean; Hyper's bias is a fraction of it.
  std::mt19937 rng(3);
  const int draws = 600;
  double bias_h = 0.0, bias_k = 0.0, var_h = 0.0;
  for (int k = 0; k < draws; ++k) {
    const Points2 p = arc(0.0, 0.0, 100.0, 0.0, M_PI / 6, 50, 0.05, rng);
    const double rh = hyper_circle_fit(p).radius - 100.0, rk = kasa_circle_fit(p).radius - 100.0;
    bias_h += rh, bias_k += rk, var_h += rh * rh;
  }
  bias_h /= draws, bias_k /= draws;
  const double sem = std::sqrt(var_h / draws - bias_h * bias_h) / std::sqrt(draws);
  INFO("mean radius error: Hyper " << bias_h << " mm, Kasa " << bias_k << " mm, standard error "
                                   << sem);
  CHECK(bias_k < -5 * sem);
  CHECK(std::abs(bias_h) < 3 * sem);
  CHECK(std::abs(bias_k) > 3 * std::abs(bias_h));
}

TEST_CASE("degenerate input is refused with a clear error", "[fit]") {
  std::mt19937 rng(4);
  Points2 two(2, 2);
  two << 0, 0, 1, 1;
  CHECK_THROWS_AS(hyper_circle_fit(two), DegenerateGeometry);
  Points2 line(5, 2);
  for (int i = 0; i < 5; ++i) line.row(i) << i, 2.0 * i + 1;
  CHECK_THROWS_WITH(hyper_circle_fit(line), Catch::Contains("collinear"));
  CHECK_THROWS_WITH(kasa_circle_fit(line), Catch::Contains("collinear"));
  // 0.5 degree of a 100 mm circle with 0.05 mm noise: sagitta 1 um, far below the scatter.
  CHECK_THROWS_WITH(hyper_circle_fit(arc(0, 0, 100, 0, M_PI / 360, 20, 0.05, rng)),
                    Catch::Contains("too short"));
  Points2 nan = arc(0, 0, 10, 0, 3, 10, 0.0, rng);
  nan(3, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(hyper_circle_fit(nan), InvalidArgument);
  CHECK_THROWS_WITH(hyper_circle_fit(nan), Catch::Contains("point 3 of 10"));
  // The caller's context names the data in every message.
  CircleFitOptions o;
  o.context = "s.csv: test radial_C";
  CHECK_THROWS_WITH(hyper_circle_fit(line, o),
                    Catch::StartsWith("s.csv: test radial_C: hyper_circle_fit: the 5 points"));
  CHECK_THROWS_WITH(kasa_circle_fit(two, o),
                    Catch::StartsWith("s.csv: test radial_C: kasa_circle_fit: 2 points"));
}

TEST_CASE("geometric refinement lowers the orthogonal residual", "[fit]") {
  std::mt19937 rng(5);
  const Points2 p = arc(5, 5, 40, 0.2, 2.0, 40, 0.02, rng);
  CircleFitOptions o;
  const CircleFit a = kasa_circle_fit(p, o);
  o.refine = true;
  const CircleFit b = kasa_circle_fit(p, o);
  CHECK(b.rms <= a.rms);
  CHECK(b.radius == Approx(hyper_circle_fit(p, o).radius).epsilon(1e-9));
}
