// Tests of the residual noise model: AR order and coefficients recovered within their
// sampling error, white noise found white, the whitener is the inverse Cholesky factor of the
// model's covariance, and whitened AR data are white.
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"

using namespace rotacal;

namespace {

struct Layout {
  std::vector<std::string> groups;
  std::vector<double> times;
};

// `streams` groups of n readings at `rate_hz` (a ballbar test each).
Layout layout(int streams, int n, double rate_hz) {
  Layout L;
  for (int s = 0; s < streams; ++s)
    for (int i = 0; i < n; ++i) {
      L.groups.push_back("test" + std::to_string(s));
      L.times.push_back(100.0 * s + i / rate_hz);
    }
  return L;
}

double autocorrelation(const Eigen::VectorXd& x, int lag) {
  const double m = x.mean();
  double num = 0.0, den = 0.0;
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    den += (x[t] - m) * (x[t] - m);
    if (t >= lag) num += (x[t] - m) * (x[t - lag] - m);
  }
  return num / den;
}

}  // namespace

TEST_CASE("white noise comes out white", "[noise_model]") {
  const Layout L = layout(20, 400, 100.0);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> N(0.0, 0.5e-3);
  Eigen::VectorXd r(static_cast<Eigen::Index>(L.groups.size()));
  for (Eigen::Index i = 0; i < r.size(); ++i) r[i] = N(rng);
  const NoiseModel M = estimate_noise_model(L.groups, L.times, r);
  REQUIRE(M.streams.size() == 20);
  int coloured = 0;
  for (const NoiseStream& s : M.streams) coloured += s.order() > 0;
  // BIC's false-positive rate per stream at n = 400 is well under 5 %: at most 2 of 20.
  CHECK(coloured <= 2);
  // Pooled sigma over 8000 readings: relative standard error 1/sqrt(2 n) = 0.8 %.
  CHECK(std::abs(M.sigma_um - 0.5) < 4 * 0.5 / std::sqrt(2.0 * 8000));
  CHECK(M.effective_samples > 0.9 * 8000);
}

TEST_CASE("AR(1) coefficient, marginal sigma and correlation time recovered", "[noise_model]") {
  const int n = 4000;
  for (double rho : {0.5, 0.9, 0.95}) {
    const Layout L = layout(1, n, 1000.0);
    const Eigen::VectorXd r = noise_gen::ar1(L.groups, L.times, rho, 0.5e-3, 11);
    const NoiseModel M = estimate_noise_model(L.groups, L.times, r);
    REQUIRE(M.streams.size() == 1);
    const NoiseStream& s = M.streams[0];
    INFO("rho " << rho << ": " << M.summary());
    REQUIRE(s.order() >= 1);
    // Asymptotic standard error of an AR(1) coefficient: sqrt((1 - rho^2) / n).
    CHECK(std::abs(s.ar[0] - rho) < 4 * std::sqrt((1 - rho * rho) / n));
    CHECK(s.order() == 1);
    // Marginal variance of correlated data: relative standard error sqrt(2 tau2 / n) with
    // tau2 = (1 + rho^2) / (1 - rho^2); sigma has half of it.
    const double tau2 = (1 + rho * rho) / (1 - rho * rho);
    CHECK(std::abs(s.marginal_sigma_um - 0.5) < 4 * 0.5 * 0.5 * std::sqrt(2 * tau2 / n));
    const double tau = (1 + rho) / (1 - rho);
    // tau = (1 + phi)/(1 - phi): its error follows from phi's, d tau / d phi = 2 / (1 - phi)^2.
    CHECK(std::abs(s.correlation_samples - tau) <
          4 * 2 / ((1 - rho) * (1 - rho)) * std::sqrt((1 - rho * rho) / n));
    CHECK(s.correlation_time_s == Approx(s.correlation_samples * 1e-3).epsilon(1e-9));
    CHECK(s.effective_samples == Approx(n / s.correlation_samples).epsilon(1e-9));
  }
}

TEST_CASE("the whitener is the inverse Cholesky factor of the AR(1) covariance", "[noise_model]") {
  const Layout L = layout(1, 3000, 100.0);
  const NoiseModel M = estimate_noise_model(L.groups, L.times, noise_gen::ar1(L.groups, L.times, 0.8, 1e-3, 3));
  REQUIRE(M.streams[0].order() == 1);
  const double phi = M.streams[0].ar[0], sx = M.streams[0].marginal_sigma_um * 1e-3;
  // Check on the first 6 readings: the covariance of a stationary AR(1) is sx^2 phi^|i-j|,
  // written here from the definition, independently of the whitener's recursion.
  NoiseModel small = M;
  small.n = 6;
  small.streams[0].rows = {0, 1, 2, 3, 4, 5};
  Eigen::MatrixXd S(6, 6);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) S(i, j) = sx * sx * std::pow(phi, std::abs(i - j));
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(6, 6);
  ArWhitener(small).apply(W);
  CHECK((W * S * W.transpose() - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff() < 1e-9);
  // Lower triangular (a causal filter) like a Cholesky factor's inverse.
  CHECK(W.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("whitened AR and 1/f-like data are white with unit variance", "[noise_model]") {
  const int n = 3000;
  const Layout L = layout(2, n, 1000.0);
  for (int kind = 0; kind < 2; ++kind) {
    const Eigen::VectorXd r = kind == 0 ? noise_gen::ar1(L.groups, L.times, 0.95, 0.5e-3, 5)
                                        : noise_gen::pink(L.groups, L.times, 0.5e-3, 5);
    const NoiseModel M = estimate_noise_model(L.groups, L.times, r);
    INFO((kind == 0 ? "AR(1) 0.95: " : "1/f-like: ") << M.summary());
    CHECK_FALSE(M.white());
    Eigen::MatrixXd w = r;
    ArWhitener(M).apply(w);
    for (int s = 0; s < 2; ++s) {
      const Eigen::VectorXd x = w.col(0).segment(s * n, n);
      // Sampling error of a white autocorrelation: 1/sqrt(n); of a variance: sqrt(2/n).
      for (int lag = 1; lag <= 5; ++lag) CHECK(std::abs(autocorrelation(x, lag)) < 4 / std::sqrt(n));
      CHECK(std::abs(x.squaredNorm() / n - 1.0) < 4 * std::sqrt(2.0 / n));
    }
    // The raw data are far from white at lag 1.
    CHECK(autocorrelation(r.head(n), 1) > 10 / std::sqrt(n));
  }
}

TEST_CASE("readings that share a time stamp are separate channels", "[noise_model]") {
  // An R-test nest: dx, dy, dz at each pose time.
  std::vector<std::string> g;
  std::vector<double> t;
  for (int pose = 0; pose < 300; ++pose)
    for (int a = 0; a < 3; ++a) g.push_back("nest 1"), t.push_back(2.0 * pose);
  std::vector<std::string> sg;
  std::vector<int> sc;
  const auto streams = noise_streams(g, t, &sg, &sc);
  REQUIRE(streams.size() == 3);
  CHECK(sc == std::vector<int>{0, 1, 2});
  CHECK(streams[1][0] == 1);
  CHECK(streams[1][1] == 4);
  // A probe zero wandering between poses is a random walk: strongly correlated per channel.
  const Eigen::VectorXd r = noise_gen::probe_zero_wander(g, t, 0.1e-3, 9) + noise_gen::ar1(g, t, 0.0, 0.3e-3, 10);
  const NoiseModel M = estimate_noise_model(g, t, r);
  CHECK(M.streams.size() == 3);
  CHECK_FALSE(M.white());
  CHECK(M.correlation_time_s > 2 * 2.0);
}

TEST_CASE("bad input to the noise model names what was wrong", "[noise_model]") {
  const Layout L = layout(1, 10, 100.0);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(9);
  CHECK_THROWS_WITH(estimate_noise_model(L.groups, L.times, r),
                    Catch::Contains("residuals has 9 entries but groups has 10"));
  r = Eigen::VectorXd::Zero(10);
  r[3] = std::nan("");
  CHECK_THROWS_WITH(estimate_noise_model(L.groups, L.times, r), Catch::Contains("residuals[3]"));
  NoiseModelOptions o;
  o.max_order = -1;
  CHECK_THROWS_AS(estimate_noise_model(L.groups, L.times, Eigen::VectorXd::Zero(10), o), InvalidArgument);
  const NoiseModel M = estimate_noise_model(L.groups, L.times, Eigen::VectorXd::Ones(10));
  Eigen::MatrixXd wrong(4, 1);
  CHECK_THROWS_WITH(ArWhitener(M).apply(wrong), Catch::Contains("4 rows given"));
  CHECK_THROWS_AS(noise_gen::ar1(L.groups, L.times, 1.0, 1e-3, 1), InvalidArgument);
}
