// SPDX-License-Identifier: BSD-3-Clause
// Tests of the residual noise model: AR order and coefficients recovered within their
// sampling error, white noise found white, the whitener is the inverse Cholesky factor of the
// model's covariance, and whitened AR data are white.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_handling.hpp"
#include "rotacal/core/noise_model.hpp"

using namespace rotacal;

namespace {

std::vector<std::vector<Eigen::Index>> noise_streams_of(const NoiseModel& M) {
  std::vector<std::vector<Eigen::Index>> rows;
  for (const NoiseStream& s : M.streams) rows.push_back(s.rows);
  return rows;
}

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
  // min_order 1 keeps Burg's lag-1 coefficient where BIC calls a stream white (the probe's
  // correlation bound needs it); with_lag1 sets it, the marginal sigma kept.
  NoiseModelOptions lag1;
  lag1.max_order = lag1.min_order = 1;
  const NoiseModel M1 = estimate_noise_model(L.groups, L.times, r, lag1);
  std::vector<double> phi;
  for (std::size_t s = 0; s < M1.streams.size(); ++s) {
    REQUIRE(M1.streams[s].order() == 1);
    if (M.streams[s].order() == 1) CHECK(M1.streams[s].ar == M.streams[s].ar);
    phi.push_back(0.5 + 0.01 * static_cast<double>(s));
  }
  const NoiseModel B = with_lag1(M1, phi);
  CHECK(B.streams[7].ar[0] == phi[7]);
  CHECK(B.streams[7].marginal_sigma_um == M1.streams[7].marginal_sigma_um);
  CHECK(B.streams[7].correlation_samples == Approx((1 + phi[7]) / (1 - phi[7])));
  CHECK_THROWS_WITH(with_lag1(M1, {0.5}), Catch::Contains("1 coefficients for 20 streams"));
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

TEST_CASE("the mean-removal bias of a short stream's AR(1) coefficient is corrected",
          "[noise_model]") {
  // 400 streams of 250 readings (a ballbar test) at rho 0.95: Burg with the mean removed is
  // about (1 + 3 rho) / n = 0.015 low on average; corrected, the mean is within its standard
  // error sqrt((1 - rho^2) / n) / sqrt(400) = 0.001 (4 of them allowed) of rho.
  const double rho = 0.95;
  const int n = 250, draws = 400;
  const Layout L = layout(1, n, 100.0);
  double raw = 0.0, corrected = 0.0;
  int ar1 = 0;
  for (int d = 0; d < draws; ++d) {
    const Eigen::VectorXd r = noise_gen::ar1(L.groups, L.times, rho, 0.5e-3, 1000 + d);
    const NoiseModel M = estimate_noise_model(L.groups, L.times, r);
    if (M.streams[0].order() != 1) continue;
    ++ar1;
    const NoiseModel C = with_mean_bias_corrected(M);
    raw += M.streams[0].ar[0];
    corrected += C.streams[0].ar[0];
    CHECK(C.streams[0].reflection[0] == C.streams[0].ar[0]);
    const double k = C.streams[0].ar[0];
    CHECK(C.streams[0].correlation_samples ==
          Approx(std::min((1 + k) / (1 - k), static_cast<double>(n))));
    CHECK(C.streams[0].innovation_sigma_um < M.streams[0].innovation_sigma_um);
  }
  REQUIRE(ar1 > draws * 9 / 10);
  raw /= ar1, corrected /= ar1;
  const double se = std::sqrt((1 - rho * rho) / n) / std::sqrt(static_cast<double>(ar1));
  INFO("mean raw " << raw << ", corrected " << corrected << ", standard error " << se);
  CHECK(rho - raw > 0.5 * (1 + 3 * rho) / n);  // the bias is there to correct
  CHECK(std::abs(corrected - rho) < 4 * se);
  // White streams and AR(2) streams are left alone.
  const Layout W = layout(2, 500, 100.0);
  const Eigen::VectorXd w = noise_gen::ar1(W.groups, W.times, 0.0, 0.5e-3, 3);
  const NoiseModel MW = estimate_noise_model(W.groups, W.times, w);
  const NoiseModel CW = with_mean_bias_corrected(MW);
  for (std::size_t k = 0; k < MW.streams.size(); ++k) CHECK(CW.streams[k].ar == MW.streams[k].ar);
}

TEST_CASE("the whitener is the inverse Cholesky factor of the AR(1) covariance", "[noise_model]") {
  const Layout L = layout(1, 3000, 100.0);
  const NoiseModel M =
      estimate_noise_model(L.groups, L.times, noise_gen::ar1(L.groups, L.times, 0.8, 1e-3, 3));
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

TEST_CASE("AR(1) inverse covariance and lag-product Gram matrix equal the whitened products",
          "[noise_model]") {
  // Two AR(1) streams with interleaved rows, a white one, an AR(1) one of a single reading,
  // and a row in no stream (the whitener leaves it as it is). V^-1 is written from the
  // definition (the inverse of each stream's sigma^2 phi^|i-j| covariance), independently of
  // the whitener's recursion.
  NoiseModel M;
  M.n = 22;
  NoiseStream a, b, w;
  for (Eigen::Index i = 0; i < 16; i += 2) a.rows.push_back(i);
  for (Eigen::Index i = 1; i < 16; i += 2) b.rows.push_back(i);
  for (Eigen::Index i = 16; i < 20; ++i) w.rows.push_back(i);
  a.reflection = a.ar = {0.8};
  a.marginal_sigma_um = 1.5;
  b.reflection = b.ar = {-0.3};
  b.marginal_sigma_um = 0.7;
  w.marginal_sigma_um = 2.0;
  NoiseStream one;  // an AR(1) stream of a single reading: its marginal variance alone
  one.rows = {21};
  one.reflection = one.ar = {0.5};
  one.marginal_sigma_um = 0.9;
  M.streams = {a, b, w, one};
  M.max_order = 1;
  Eigen::MatrixXd Vinv = Eigen::MatrixXd::Identity(22, 22);
  for (const NoiseStream& s : M.streams) {
    const Eigen::Index m = static_cast<Eigen::Index>(s.rows.size());
    const double phi = s.ar.empty() ? 0.0 : s.ar[0], sx = s.marginal_sigma_um * 1e-3;
    Eigen::MatrixXd C(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j)
        C(i, j) = sx * sx * std::pow(phi, std::abs(static_cast<double>(i - j)));
    const Eigen::MatrixXd Ci = C.inverse();
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j)
        Vinv(s.rows[static_cast<std::size_t>(i)], s.rows[static_cast<std::size_t>(j)]) = Ci(i, j);
  }
  std::mt19937 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::MatrixXd J(22, 4);
  for (Eigen::Index i = 0; i < J.size(); ++i) J.data()[i] = N(rng);
  J.col(2) *= 1e-3;  // columns of different units
  const ArWhitener W(M);
  REQUIRE(W.ar1_only());
  Eigen::MatrixXd VJ = J;
  W.apply_inverse_covariance(VJ);
  const Eigen::MatrixXd expect = Vinv * J;
  CHECK((VJ - expect).cwiseAbs().maxCoeff() < 1e-9 * expect.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd G = W.gram(StreamLagProducts(J, noise_streams_of(M)));
  const Eigen::MatrixXd G_expect = J.transpose() * Vinv * J;
  CHECK((G - G_expect).cwiseAbs().maxCoeff() < 1e-9 * G_expect.cwiseAbs().maxCoeff());
  // Lag products of other streams, and models it does not cover, are refused by name.
  CHECK_THROWS_WITH(W.gram(StreamLagProducts(J, {a.rows, b.rows})), Catch::Contains("streams"));
  NoiseModel ar2 = M;
  ar2.streams[0].reflection = {0.5, 0.2};
  ar2.max_order = 2;
  CHECK_FALSE(ArWhitener(ar2).ar1_only());
  CHECK_THROWS_AS(ArWhitener(ar2).apply_inverse_covariance(VJ), InvalidArgument);
}

TEST_CASE("AR(2) autocovariance from the reflection coefficients agrees with the whitener",
          "[noise_model]") {
  // The autocovariance (Levinson read backwards, then the AR recursion) and the whitener (the
  // forward recursion of prediction errors) are computed independently: W C W^T = I ties them.
  NoiseModel M;
  M.n = 40;
  NoiseStream st;
  for (Eigen::Index i = 0; i < 40; ++i) st.rows.push_back(i);
  st.reflection = {0.7, -0.4};
  st.ar = {0.7 * (1 + 0.4), -0.4};  // phi_1 = k_1 (1 - k_2), phi_2 = k_2
  st.marginal_sigma_um = 2.0;
  M.streams = {st};
  M.max_order = 2;
  const std::vector<double> g = ar_autocovariance(st, 40);
  // Yule-Walker: gamma_k = phi_1 gamma_{k-1} + phi_2 gamma_{k-2} for k >= 1 (gamma_-1 = gamma_1).
  CHECK(g[1] == Approx(st.ar[0] * g[0] + st.ar[1] * g[1]).epsilon(1e-12));
  CHECK(g[5] == Approx(st.ar[0] * g[4] + st.ar[1] * g[3]).epsilon(1e-12));
  const Eigen::MatrixXd C = stream_covariance(st);
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(40, 40);
  ArWhitener(M).apply(W);
  CHECK((W * C * W.transpose() - Eigen::MatrixXd::Identity(40, 40)).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("a stream with a random walk is whitened by its covariance's Cholesky factor",
          "[noise_model]") {
  NoiseModel M;
  M.n = 30;
  NoiseStream st;
  for (Eigen::Index i = 0; i < 30; ++i) st.rows.push_back(29 - i);  // reversed: rows map back
  st.reflection = st.ar = {0.6};
  st.marginal_sigma_um = 0.3;
  st.random_walk_step_um = 0.1;
  M.streams = {st};
  M.max_order = 1;
  M.random_walk_step_um = 0.1;
  CHECK_FALSE(M.white());
  // Covariance from the definition, in row order (row r is position 29 - r in the stream).
  Eigen::MatrixXd S(30, 30);
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 30; ++c) {
      const int i = 29 - r, j = 29 - c;
      S(r, c) = 0.09e-6 * std::pow(0.6, std::abs(i - j)) + 0.01e-6 * std::min(i, j);
    }
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(30, 30);
  ArWhitener(M).apply(W);  // AR(1) + walk: the Kalman innovations (ArWalkFilter)
  CHECK((W * S * W.transpose() - Eigen::MatrixXd::Identity(30, 30)).cwiseAbs().maxCoeff() < 1e-8);
  // In stream order the filter is causal (lower triangular) and its log-determinant is ln|S|.
  const ArWalkFilter f(30, 0.09e-6, 0.6, 0.01e-6);
  Eigen::MatrixXd Wf = Eigen::MatrixXd::Identity(30, 30);
  std::vector<Eigen::Index> rows(30);
  for (Eigen::Index i = 0; i < 30; ++i) rows[static_cast<std::size_t>(i)] = i;
  f.apply(rows, Wf);
  CHECK(Wf.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff() == 0.0);
  Eigen::MatrixXd Sf(30, 30);
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j)
      Sf(i, j) = 0.09e-6 * std::pow(0.6, std::abs(i - j)) + 0.01e-6 * std::min(i, j);
  const Eigen::LLT<Eigen::MatrixXd> llt(Sf);
  CHECK(f.log_det() ==
        Approx(2.0 * Eigen::MatrixXd(llt.matrixL()).diagonal().array().log().sum()).epsilon(1e-10));
  // AR(2) + walk: the dense Cholesky path.
  st.reflection = {0.6, -0.3};
  st.ar = {0.6 * 1.3, -0.3};
  M.streams = {st};
  M.max_order = 2;
  Eigen::MatrixXd S2 = stream_covariance(st);  // in stream order; rows are reversed
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(30, 30);
  for (int i = 0; i < 30; ++i) P(29 - i, i) = 1.0;
  S2 = P * S2 * P.transpose();
  Eigen::MatrixXd W2 = Eigen::MatrixXd::Identity(30, 30);
  ArWhitener(M).apply(W2);
  CHECK((W2 * S2 * W2.transpose() - Eigen::MatrixXd::Identity(30, 30)).cwiseAbs().maxCoeff() <
        1e-8);
}

namespace {
// An R-test-like layout: 6 streams of 84 readings; the fit takes a level per stream and five
// smooth functions of the position shared by all streams (as an R-test's B polynomials, B
// running outer), which absorb most of a random walk.
struct RemlCase {
  std::vector<std::string> groups;
  std::vector<double> times;
  Eigen::MatrixXd X;
};
RemlCase reml_case() {
  RemlCase c;
  const int S = 6, n = 84;
  c.X = Eigen::MatrixXd::Zero(S * n, S + 5);
  for (int s = 0; s < S; ++s)
    for (int i = 0; i < n; ++i) {
      const int r = s * n + i;
      c.groups.push_back("nest" + std::to_string(s));
      c.times.push_back(6.0 * i);
      c.X(r, s) = 1.0;
      const double b = (i / 12 - 3) / 3.0;  // B steps every 12 poses, -1..1
      for (int k = 1; k <= 5; ++k) c.X(r, S + k - 1) = std::pow(b, k);
    }
  return c;
}
Eigen::VectorXd project_out(const Eigen::MatrixXd& X, const Eigen::VectorXd& e) {
  return e - X * X.colPivHouseholderQr().solve(e);
}
}  // namespace

// Var(x_{t+h} - x_t) of a stream model: 2 (gamma_0 - gamma_h) + q^2 h (um^2).
double variogram(const NoiseStream& s, std::size_t h) {
  const std::vector<double> g = ar_autocovariance(s, h + 1);
  return (2.0 * (g[0] - g[h]) +
          std::pow(s.random_walk_step_um * 1e-3, 2) * static_cast<double>(h)) *
         1e6;
}

TEST_CASE("REML recovers AR(1) + random walk from what a fit leaves; white stays white",
          "[noise_model]") {
  // 84 readings per stream cannot tell a walk from an AR(1) near 1 session by session (the
  // likelihood has a ridge along rho-lambda), but the covariance they imply can be checked:
  // the variogram Var(x_{t+h} - x_t), which the parameters' sigmas rest on, at short and long
  // lags. Truth: rho 0.9, sigma 0.3 um, step 0.1 um: 2 0.09 (1 - 0.9^h) + 0.01 h um^2.
  const RemlCase c = reml_case();
  const int K = 12;
  const std::size_t lags[3] = {1, 10, 40};
  double reml_v[3] = {0, 0, 0}, burg_v[3] = {0, 0, 0}, white_v40 = 0.0, q_white = 0.0,
         rho_white = 0.0;
  for (int k = 0; k < K; ++k) {
    const Eigen::VectorXd e = noise_gen::ar1(c.groups, c.times, 0.9, 0.3e-3, 100 + k) +
                              noise_gen::probe_zero_wander(c.groups, c.times, 0.1e-3, 200 + k);
    const Eigen::VectorXd r = project_out(c.X, e);
    const NoiseModel burg = estimate_noise_model(c.groups, c.times, r);
    const NoiseModel M = estimate_noise_model_reml(burg, r, c.X);
    REQUIRE(M.streams.size() == 6);
    for (int l = 0; l < 3; ++l)
      for (int s = 0; s < 6; ++s) {
        reml_v[l] += variogram(M.streams[static_cast<std::size_t>(s)], lags[l]) / (6 * K);
        burg_v[l] += variogram(burg.streams[static_cast<std::size_t>(s)], lags[l]) / (6 * K);
      }
    // White noise: no walk, no correlation, the variogram flat at 2 sigma^2.
    std::mt19937_64 rng(300 + k);
    std::normal_distribution<double> N(0.0, 0.3e-3);
    Eigen::VectorXd w(c.X.rows());
    for (Eigen::Index i = 0; i < w.size(); ++i) w[i] = N(rng);
    const Eigen::VectorXd rw = project_out(c.X, w);
    const NoiseModel Mw =
        estimate_noise_model_reml(estimate_noise_model(c.groups, c.times, rw), rw, c.X);
    q_white += Mw.random_walk_step_um / K, rho_white += Mw.streams[0].ar[0] / K;
    white_v40 += variogram(Mw.streams[0], 40) / K;
  }
  double truth[3];
  for (int l = 0; l < 3; ++l)
    truth[l] = 2 * 0.09 * (1 - std::pow(0.9, static_cast<double>(lags[l]))) +
               0.01 * static_cast<double>(lags[l]);
  INFO("variogram at lags 1, 10, 40 (um^2): truth "
       << truth[0] << ", " << truth[1] << ", " << truth[2] << "; REML " << reml_v[0] << ", "
       << reml_v[1] << ", " << reml_v[2] << "; Burg on the residuals " << burg_v[0] << ", "
       << burg_v[1] << ", " << burg_v[2] << "; white: rho " << rho_white << ", walk " << q_white
       << " um, lag 40 " << white_v40);
  // Means over 12 sessions x 6 streams: within 25 % (the session-to-session spread is ~40 %).
  for (int l = 0; l < 3; ++l) CHECK(reml_v[l] == Approx(truth[l]).epsilon(0.25));
  // What the old estimate missed: the residuals' Burg model sees the long lags far too small.
  CHECK(burg_v[2] < 0.6 * truth[2]);
  CHECK(std::abs(rho_white) < 0.05);
  CHECK(q_white < 0.02);
  CHECK(white_v40 == Approx(2 * 0.09).epsilon(0.1));
  CHECK_THROWS_WITH(estimate_noise_model_reml(NoiseModel{}, Eigen::VectorXd::Zero(3),
                                              Eigen::MatrixXd::Zero(3, 1)),
                    Catch::Contains("must agree"));
}

TEST_CASE("REML and the bias factor of a long stream hold memory linear in it (issue 57)",
          "[noise_model]") {
  // 150,000 readings in one stream (a probe session of that many touches is one stream): an
  // n x n matrix of them is 180 GB, which this test would not survive; what is linear is a few
  // MB. The correlation time REML reports is 1^T C 1 / tr C of the stream's covariance, checked
  // on a short stream against the dense matrix (stream_covariance), summed here.
  const int n = 150000;
  const Layout L = layout(1, n, 10.0);
  Eigen::MatrixXd X(n, 2);
  for (int i = 0; i < n; ++i) X(i, 0) = 1.0, X(i, 1) = static_cast<double>(i) / n;
  const Eigen::VectorXd e = noise_gen::ar1(L.groups, L.times, 0.6, 0.5e-3, 17) +
                            noise_gen::probe_zero_wander(L.groups, L.times, 0.002e-3, 18);
  const Eigen::VectorXd r = project_out(X, e);
  const NoiseModel burg = estimate_noise_model(L.groups, L.times, r);
  const NoiseModel M = estimate_noise_model_reml(burg, r, X);
  REQUIRE(M.streams.size() == 1);
  CHECK(M.streams[0].ar[0] == Approx(0.6).margin(0.05));
  const double f = noise_model_bias_factor(burg, L.groups, L.times, X, NoiseModelOptions{}, 2, 5);
  CHECK(f >= 1.0);
  CHECK(std::isfinite(f));

  const int m = 60;
  const Layout S = layout(1, m, 10.0);
  Eigen::MatrixXd Xs = Eigen::MatrixXd::Ones(m, 1);
  const Eigen::VectorXd es = noise_gen::ar1(S.groups, S.times, 0.7, 0.5e-3, 21) +
                             noise_gen::probe_zero_wander(S.groups, S.times, 0.1e-3, 22);
  const Eigen::VectorXd rs = project_out(Xs, es);
  const NoiseModel Ms =
      estimate_noise_model_reml(estimate_noise_model(S.groups, S.times, rs), rs, Xs);
  const Eigen::MatrixXd C = stream_covariance(Ms.streams[0]);
  CHECK(Ms.streams[0].correlation_samples ==
        Approx(std::min<double>(m, std::max(1e-3, C.sum() / C.trace()))).epsilon(1e-9));
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
      for (int lag = 1; lag <= 5; ++lag)
        CHECK(std::abs(autocorrelation(x, lag)) < 4 / std::sqrt(n));
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
  const Eigen::VectorXd r =
      noise_gen::probe_zero_wander(g, t, 0.1e-3, 9) + noise_gen::ar1(g, t, 0.0, 0.3e-3, 10);
  const NoiseModel M = estimate_noise_model(g, t, r);
  CHECK(M.streams.size() == 3);
  CHECK_FALSE(M.white());
  CHECK(M.correlation_time_s > 2 * 2.0);
}

TEST_CASE("streams: groups in order of first appearance, rows in time order", "[noise_model]") {
  // A label that comes back after another one, rows out of time order within a group, and
  // a time stamp shared by two readings (channels) in the group that comes back.
  const std::vector<std::string> g = {"b", "b", "a", "a", "b", "a", "a", "b"};
  const std::vector<double> t = {3.0, 1.0, 0.5, 1.5, 2.0, 1.5, 0.2, 4.0};
  std::vector<std::string> sg;
  std::vector<int> sc;
  const auto streams = noise_streams(g, t, &sg, &sc);
  CHECK(sg == std::vector<std::string>{"b", "a", "a"});
  CHECK(sc == std::vector<int>{0, 0, 1});
  REQUIRE(streams.size() == 3);
  // b at 1, 2, 3, 4 s; a at 0.2, 0.5, 1.5 (first of the pair, file order), and the second 1.5.
  CHECK(streams[0] == std::vector<Eigen::Index>{1, 4, 0, 7});
  CHECK(streams[1] == std::vector<Eigen::Index>{6, 2, 3});
  CHECK(streams[2] == std::vector<Eigen::Index>{5});
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
  CHECK_THROWS_AS(estimate_noise_model(L.groups, L.times, Eigen::VectorXd::Zero(10), o),
                  InvalidArgument);
  const NoiseModel M = estimate_noise_model(L.groups, L.times, Eigen::VectorXd::Ones(10));
  Eigen::MatrixXd wrong(4, 1);
  CHECK_THROWS_WITH(ArWhitener(M).apply(wrong), Catch::Contains("4 rows given"));
  CHECK_THROWS_AS(noise_gen::ar1(L.groups, L.times, 1.0, 1e-3, 1), InvalidArgument);
}

TEST_CASE("Burg's reflection coefficients agree with the textbook recursion", "[noise_model]") {
  // The library's Burg runs on vector segments; this is the per-sample recursion (Burg 1975,
  // as in Kay, Modern Spectral Estimation, Sec. 7.4) on one AR(2) stream of 400 readings.
  const Layout L = layout(1, 400, 100.0);
  Eigen::VectorXd x(400);
  std::mt19937 rng(17);
  std::normal_distribution<double> N(0.0, 1e-3);
  x[0] = N(rng), x[1] = N(rng);
  for (Eigen::Index t = 2; t < x.size(); ++t) x[t] = 1.2 * x[t - 1] - 0.5 * x[t - 2] + N(rng);
  const NoiseModel M = estimate_noise_model(L.groups, L.times, x);
  REQUIRE(M.streams.size() == 1);
  const std::vector<double>& k = M.streams[0].reflection;
  REQUIRE(k.size() == 2);  // BIC picks the simulated order
  std::vector<double> f(x.data(), x.data() + x.size());
  for (double& v : f) v -= x.mean();
  std::vector<double> b = f;
  for (std::size_t m = 1; m <= k.size(); ++m) {
    double num = 0.0, den = 0.0;
    for (std::size_t t = m; t < f.size(); ++t)
      num += f[t] * b[t - 1], den += f[t] * f[t] + b[t - 1] * b[t - 1];
    const double km = 2.0 * num / den;
    CHECK(k[m - 1] == Approx(km).epsilon(1e-12));
    for (std::size_t t = f.size() - 1; t >= m; --t) {
      const double ft = f[t], bt1 = b[t - 1];
      f[t] = ft - km * bt1, b[t] = bt1 - km * ft;
    }
  }
}

TEST_CASE("a noise model on a stream layout built once equals the one from groups and times",
          "[noise_model]") {
  // The diagnosis builds the layout once and models many residual vectors on it; the structure
  // test models the other groups' residuals on layout.except_group(g).
  Layout L = layout(3, 120, 200.0);
  const Eigen::VectorXd r = noise_gen::ar1(L.groups, L.times, 0.7, 0.5e-3, 23);
  const NoiseStreamLayout layout_all(L.groups, L.times);
  for (bool pooled : {false, true}) {
    NoiseModelOptions o;
    o.pooled = pooled;
    const NoiseModel a = estimate_noise_model(L.groups, L.times, r, o);
    const NoiseModel b = estimate_noise_model(layout_all, r, o);
    REQUIRE(a.streams.size() == b.streams.size());
    for (std::size_t s = 0; s < a.streams.size(); ++s) {
      CHECK(a.streams[s].rows == b.streams[s].rows);
      CHECK(a.streams[s].reflection == b.streams[s].reflection);
      CHECK(a.streams[s].sample_interval_s == b.streams[s].sample_interval_s);
    }
    // Without test1: as if the session had only test0 and test2.
    std::vector<std::string> g;
    std::vector<double> t;
    std::vector<double> rv;
    for (std::size_t i = 0; i < L.groups.size(); ++i)
      if (L.groups[i] != "test1")
        g.push_back(L.groups[i]), t.push_back(L.times[i]),
            rv.push_back(r[static_cast<Eigen::Index>(i)]);
    const NoiseModel c = estimate_noise_model(
        g, t, Eigen::Map<const Eigen::VectorXd>(rv.data(), static_cast<Eigen::Index>(rv.size())),
        o);
    const NoiseModel d = estimate_noise_model(layout_all.except_group("test1"), r, o);
    REQUIRE(c.streams.size() == 2);
    REQUIRE(d.streams.size() == 2);
    for (std::size_t s = 0; s < 2; ++s) {
      CHECK(c.streams[s].group == d.streams[s].group);
      CHECK(c.streams[s].reflection == d.streams[s].reflection);
      CHECK(c.streams[s].marginal_sigma_um ==
            Approx(d.streams[s].marginal_sigma_um).epsilon(1e-12));
    }
  }
  CHECK_THROWS_WITH(estimate_noise_model(layout_all, Eigen::VectorXd::Zero(5)),
                    Catch::Contains("residuals has 5 entries but the session has 360 readings"));
}

TEST_CASE("pooled by session: each session's streams share their own AR coefficients",
          "[noise_model]") {
  // A diagnosis of several sessions names its groups "session:group" (multi_session.hpp): a
  // ballbar's streams at rho 0.8 and a probe's at 0.2 keep their own coefficients.
  std::vector<std::string> groups;
  std::vector<double> times;
  Eigen::VectorXd r(4 * 600);
  for (int s = 0; s < 4; ++s) {
    const Layout L = layout(1, 600, 10.0);
    const double rho = s < 2 ? 0.8 : 0.2;
    r.segment(600 * s, 600) = noise_gen::ar1(L.groups, L.times, rho, 0.5e-3, 31 + s);
    for (int i = 0; i < 600; ++i) {
      groups.push_back((s < 2 ? "bb:test" : "probe:touches") + std::to_string(s));
      times.push_back(L.times[static_cast<std::size_t>(i)]);
    }
  }
  NoiseModelOptions o;
  o.pooled = true;
  const NoiseModel one = estimate_noise_model(groups, times, r, o);
  o.pool_by_session = true;
  const NoiseModel each = estimate_noise_model(groups, times, r, o);
  REQUIRE(each.streams.size() == 4);
  CHECK(one.streams[0].reflection == one.streams[3].reflection);  // one set for all
  CHECK(each.streams[0].reflection == each.streams[1].reflection);
  CHECK(each.streams[2].reflection == each.streams[3].reflection);
  REQUIRE(each.streams[0].order() >= 1);
  // 1200 readings a session: an AR(1) coefficient's standard error is about 0.02-0.03.
  CHECK(std::abs(each.streams[0].ar[0] - 0.8) < 0.1);
  CHECK((each.streams[3].order() == 0 || std::abs(each.streams[3].ar[0] - 0.2) < 0.1));
}
