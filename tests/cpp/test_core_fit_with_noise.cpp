// SPDX-License-Identifier: BSD-3-Clause
// core/fit_with_noise.hpp: the white fit, the noise model of its residuals and the GLS refit,
// on a straight line y = a + b t whose noise is white or AR(1) (drawn here, seeded).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "rotacal/core/fit_with_noise.hpp"

using namespace rotacal;

namespace {
// r_i = a + b t_i - y_i.
class Line : public ResidualModel {
 public:
  Line(Eigen::VectorXd t, Eigen::VectorXd y) : t_(std::move(t)), y_(std::move(y)) {}
  Eigen::Index num_residuals() const override { return t_.size(); }
  int num_parameters() const override { return 2; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    r = (x[0] + x[1] * t_.array() - y_.array()).matrix();
    if (J) J->col(0).setOnes(), J->col(1) = t_;
  }

 private:
  Eigen::VectorXd t_, y_;
};

struct Case {
  Eigen::VectorXd t, y;
  std::vector<std::string> groups;
  std::vector<double> times;
};

// 600 readings of y = 0.5 + 0.01 t (mm, t in s) with AR(1) noise of coefficient rho, 1 um.
Case line_case(double rho, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1e-3 * std::sqrt(1.0 - rho * rho));
  Case c;
  const int n = 600;
  c.t.resize(n), c.y.resize(n);
  double e = 0.0;
  for (int i = 0; i < 200; ++i) e = rho * e + N(rng);  // stationary start
  for (int i = 0; i < n; ++i) {
    e = rho * e + N(rng);
    c.t[i] = 0.1 * i;
    c.y[i] = 0.5 + 0.01 * c.t[i] + e;
    c.groups.push_back("one");
    c.times.push_back(c.t[i]);
  }
  return c;
}

NoiseFit fit(const Case& c, NoiseHandling handling, JointFitSettings settings = {},
             bool groups = true) {
  const Line model(c.t, c.y);
  const std::vector<FitParameter> params = {{"a", "mm", 0.0}, {"b", "mm", 0.0}};
  settings.sigma = 1e-3;
  NoiseFitOptions o;
  o.noise = handling;
  return fit_with_noise([&](const JointFitSettings& s) { return solve_joint(model, params, s); },
                        settings, groups ? c.groups : std::vector<std::string>{}, c.times, o);
}
}  // namespace

TEST_CASE("white noise: one fit, a white noise model, no refit") {
  const NoiseFit f = fit(line_case(0.0, 7), NoiseHandling::automatic);
  CHECK_FALSE(f.refit);
  CHECK(f.noise.n == 600);
  CHECK(f.scale == 1.0);
  CHECK(f.fit.values[1] == Approx(0.01).margin(5e-6));
}

TEST_CASE("AR(1) noise: the GLS refit, its slope's sigma larger than the white fit's") {
  const Case c = line_case(0.9, 11);
  const NoiseFit white = fit(c, NoiseHandling::white);
  const NoiseFit gls = fit(c, NoiseHandling::automatic);
  CHECK_FALSE(white.refit);
  REQUIRE(gls.refit);
  CHECK_FALSE(gls.reml);  // not allowed unless asked
  CHECK(gls.scale >= 1.0);
  CHECK_FALSE(gls.noise.white());
  // With rho 0.9 the long-run variance is (1 + rho) / (1 - rho) = 19 times the white one: the
  // slope's 1 sigma must grow by well over 2.
  CHECK(gls.fit.estimates[1].std > 2.0 * white.fit.estimates[1].std);
  // The refit used the noise model: its summary is the whitened chi-square, near 1.
  CHECK(gls.fit.summary.chi2_per_dof == Approx(1.0).margin(0.3));
}

TEST_CASE("a caller's whitener or no streams: one fit, no noise model") {
  const Case c = line_case(0.9, 13);
  JointFitSettings with;
  with.whitener = std::make_shared<ArWhitener>(fit(c, NoiseHandling::white).noise);
  const NoiseFit given = fit(c, NoiseHandling::automatic, with);
  CHECK_FALSE(given.refit);
  CHECK(given.noise.n == 0);
  const NoiseFit none = fit(c, NoiseHandling::automatic, {}, false);
  CHECK_FALSE(none.refit);
  CHECK(none.noise.n == 0);
}

TEST_CASE("streams that do not name every residual are refused") {
  const Case c = line_case(0.0, 17);
  const Line model(c.t, c.y);
  const std::vector<FitParameter> params = {{"a", "mm", 0.0}, {"b", "mm", 0.0}};
  const auto solve = [&](const JointFitSettings& s) { return solve_joint(model, params, s); };
  const std::vector<std::string> short_groups(c.groups.begin() + 1, c.groups.end());
  CHECK_THROWS_AS(
      fit_with_noise(solve, JointFitSettings{}, short_groups, c.times, NoiseFitOptions{}),
      InvalidArgument);
}
