// SPDX-License-Identifier: BSD-3-Clause
// Tests of the joint-fit driver: batched Jets against finite differences, observability,
// GLS with a whitener against Monte Carlo on AR(1) noise, refits against fresh fits.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <type_traits>

#include "rotacal/ballbar/model.hpp"
#include "rotacal/core/joint_fit.hpp"

using namespace rotacal;

namespace {

// y(t) = A sin(w t + phase) + c + d t: nonlinear in the phase and the frequency.
struct SineModel : ResidualModel {
  Eigen::VectorXd t, y;
  Eigen::Index num_residuals() const override { return t.size(); }
  int num_parameters() const override { return 5; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    const auto f = [this](Eigen::Index i, const auto* p, auto* out) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      using std::sin;
      out[0] = p[0] * sin(p[1] * T(t[i]) + p[2]) + p[3] + p[4] * T(t[i]) - T(y[i]);
    };
    evaluate_with_jets(f, t.size(), 1, x, r, J);
  }
};

// Starts near the truth (the driver is a local solver); scales: plausible sizes of each.
std::vector<FitParameter> sine_parameters() {
  return {{"A", "mm", 1.1, 0.1},
          {"w", "rad", 0.518, 0.01},
          {"phase", "rad", 0.3, 0.1},
          {"c", "mm", 0.0, 0.1},
          {"d", "mm/s", 0.0, 0.01}};
}

// AR(1) prewhitening for e_i = phi e_{i-1} + s w_i (stationary, w white with unit variance):
// z_0 = sqrt(1 - phi^2) e_0 / s, z_i = (e_i - phi e_{i-1}) / s.
class Ar1Whitener : public ResidualWhitener {
 public:
  Ar1Whitener(Eigen::Index n, double phi, double s) : n_(n), phi_(phi), s_(s) {}
  void apply(Eigen::Ref<Eigen::MatrixXd> c) const override {
    for (Eigen::Index j = 0; j < c.cols(); ++j) {
      for (Eigen::Index i = c.rows() - 1; i >= 1; --i)
        c(i, j) = (c(i, j) - phi_ * c(i - 1, j)) / s_;
      c(0, j) *= std::sqrt(1.0 - phi_ * phi_) / s_;
    }
  }
  Eigen::Index size() const override { return n_; }

 private:
  Eigen::Index n_;
  double phi_, s_;
};

Eigen::VectorXd ar1_noise(Eigen::Index n, double phi, double s, std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::VectorXd e(n);
  e[0] = s / std::sqrt(1.0 - phi * phi) * N(rng);
  for (Eigen::Index i = 1; i < n; ++i) e[i] = phi * e[i - 1] + s * N(rng);
  return e;
}

}  // namespace

TEST_CASE("batched Jets give the Jacobian of the one ballbar model, over several passes",
          "[joint_fit]") {
  // 11 + 20 effect parameters: passes of 16, 12 and the model's own composition.
  EffectModel fx;
  for (const char* id : {"radial_motion_C_h2", "tilt_motion_A_h1", "gravity_sag_A", "coning_A",
                         "angular_positioning_C_h1", "axial_motion_C_h3", "linear_scale_X",
                         "thermal_drift_Y", "ballbar_length_offset", "rotary_zero_offset_A"})
    fx.effects.push_back(Effect::parse(id));
  const int p = 11 + fx.num_params();
  REQUIRE(p > 16);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const int n = 40;
  std::vector<Eigen::Vector3d> xyz;
  std::vector<RotaryAngles<double>> ang;
  for (int i = 0; i < n; ++i) {
    xyz.emplace_back(100 * U(rng), 100 * U(rng), 80 + 40 * U(rng));
    ang.push_back({1.5 * U(rng), 3.0 * U(rng)});
  }
  const auto f = [&](Eigen::Index i, const auto* x, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(x)>>;
    const std::size_t k = static_cast<std::size_t>(i);
    out[0] = predicted_length<T>(MachineType::AC_trt, LocationErrors<T>::from_ptr(x),
                                 Vec3<T>(x[8], x[9], x[10]), fx, x + 11, xyz[k], ang[k], 10.0 * i,
                                 RotaryMotion{});
  };
  Eigen::VectorXd x(p);
  for (int j = 0; j < p; ++j) x[j] = 1e-4 * U(rng);
  x.segment<3>(8) = Eigen::Vector3d(120, 5, 60);
  Eigen::VectorXd r(n), r2(n), rp(n), rm(n);
  Eigen::MatrixXd J(n, p);
  evaluate_with_jets(f, n, 1, x, r, &J);
  evaluate_with_jets(f, n, 1, x, r2, nullptr);
  CHECK((r - r2).cwiseAbs().maxCoeff() < 1e-12);
  for (int j = 0; j < p; ++j) {
    const double h = 1e-6;
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += h, xm[j] -= h;
    evaluate_with_jets(f, n, 1, xp, rp, nullptr);
    evaluate_with_jets(f, n, 1, xm, rm, nullptr);
    const Eigen::VectorXd fd = (rp - rm) / (2 * h);
    INFO("parameter " << j);
    CHECK((J.col(j) - fd).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + fd.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("solve_joint recovers a nonlinear model and reports its covariance", "[joint_fit]") {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  SineModel m;
  const int n = 400;
  m.t = Eigen::VectorXd::LinSpaced(n, 0.0, 40.0);
  const double A = 1.2, w = 0.52, ph = 0.25, c = 0.1, d = -0.003, s = 0.01;
  m.y.resize(n);
  for (int i = 0; i < n; ++i) m.y[i] = A * std::sin(w * m.t[i] + ph) + c + d * m.t[i] + s * N(rng);
  JointFitSettings set;
  set.sigma = s;
  const JointFitOutcome out = solve_joint(m, sine_parameters(), set);
  CHECK(out.summary.converged);
  CHECK(out.unobservable.empty());
  const double truth[5] = {A, w, ph, c, d};
  for (int j = 0; j < 5; ++j) {
    INFO(out.estimates[static_cast<std::size_t>(j)].name);
    CHECK(std::abs(out.values[j] - truth[j]) <=
          4.0 * out.estimates[static_cast<std::size_t>(j)].std);
  }
  CHECK(out.summary.chi2_per_dof == Approx(1.0).margin(4.0 * std::sqrt(2.0 / n)));
  // The gradient vanishes at the solution: J^T r = 0 relative to |J||r|.
  const Eigen::VectorXd g = out.jacobian.transpose() * out.residuals;
  for (int j = 0; j < 5; ++j)
    CHECK(std::abs(g[j]) <= 1e-6 * out.jacobian.col(j).norm() * out.residuals.norm());
}

TEST_CASE("solve_joint holds one parameter per invisible combination and says so", "[joint_fit]") {
  // c and c2 only appear as a sum: one must be fixed and both reported unobservable.
  struct Degenerate : ResidualModel {
    Eigen::VectorXd t, y;
    Eigen::Index num_residuals() const override { return t.size(); }
    int num_parameters() const override { return 3; }
    void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                  Eigen::MatrixXd* J) const override {
      const auto f = [this](Eigen::Index i, const auto* p, auto* out) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        out[0] = p[0] * T(t[i]) + p[1] + p[2] - T(y[i]);
      };
      evaluate_with_jets(f, t.size(), 1, x, r, J);
    }
  } m;
  m.t = Eigen::VectorXd::LinSpaced(50, -1.0, 1.0);
  m.y = 0.3 * m.t.array() + 0.2;
  JointFitSettings set;
  set.sigma = 1e-3;
  const JointFitOutcome out =
      solve_joint(m, {{"slope", "mm/mm", 0.0, 1.0}, {"c", "mm", 0.0}, {"c2", "mm", 0.0}}, set);
  CHECK(out.summary.converged);
  REQUIRE(out.unobservable.size() == 1);
  CHECK(out.unobservable[0].find("changes no reading") != std::string::npos);
  CHECK(out.estimates[0].observable);
  CHECK_FALSE(out.estimates[1].observable);
  CHECK_FALSE(out.estimates[2].observable);
  CHECK(out.free[1] != out.free[2]);
  CHECK(out.values[0] == Approx(0.3).margin(1e-9));
  CHECK(out.values[1] + out.values[2] == Approx(0.2).margin(1e-9));
}

TEST_CASE("with an AR(1) whitener the covariance matches the Monte Carlo spread; white does not",
          "[joint_fit]") {
  // Strongly correlated noise (phi = 0.8): the white fit's reported sigma is ~3x too small
  // ((1 + phi) / (1 - phi) inflation of the variance of slowly varying parameters); the GLS
  // fit's (Jw^T Jw)^-1 is right. 300 draws: the spread's own relative error is ~4 %.
  const double phi = 0.8, s = 0.01;
  const int n = 300, draws = 300;
  SineModel m;
  m.t = Eigen::VectorXd::LinSpaced(n, 0.0, 30.0);
  Eigen::VectorXd clean(n);
  for (int i = 0; i < n; ++i)
    clean[i] = 1.2 * std::sin(0.52 * m.t[i] + 0.25) + 0.1 - 0.003 * m.t[i];
  JointFitSettings white, gls;
  white.sigma = s;
  gls.whitener = std::make_shared<Ar1Whitener>(n, phi, s);
  std::mt19937_64 rng(17);
  Eigen::MatrixXd v_white(draws, 5), v_gls(draws, 5);
  Eigen::VectorXd std_white = Eigen::VectorXd::Zero(5), std_gls = Eigen::VectorXd::Zero(5);
  double chi2_gls = 0.0;
  for (int k = 0; k < draws; ++k) {
    m.y = clean + ar1_noise(n, phi, s, rng);
    const JointFitOutcome a = solve_joint(m, sine_parameters(), white);
    const JointFitOutcome b = solve_joint(m, sine_parameters(), gls);
    REQUIRE(a.summary.converged);
    REQUIRE(b.summary.converged);
    CHECK(b.summary.whitened);
    v_white.row(k) = a.values.transpose();
    v_gls.row(k) = b.values.transpose();
    for (int j = 0; j < 5; ++j)
      std_white[j] += a.estimates[static_cast<std::size_t>(j)].std / draws,
          std_gls[j] += b.estimates[static_cast<std::size_t>(j)].std / draws;
    chi2_gls += b.summary.chi2_per_dof / draws;
  }
  const auto spread = [&](const Eigen::MatrixXd& v, int j) {
    const Eigen::ArrayXd c = v.col(j).array() - v.col(j).mean();
    return std::sqrt((c * c).sum() / (draws - 1));
  };
  for (int j = 0; j < 5; ++j) {
    INFO("parameter " << j << ": GLS reported " << std_gls[j] << ", spread " << spread(v_gls, j)
                      << "; white reported " << std_white[j] << ", spread " << spread(v_white, j));
    CHECK(spread(v_gls, j) / std_gls[j] == Approx(1.0).margin(0.15));
  }
  // Offset and trend vary slowly: white noise theory underestimates them the most.
  CHECK(spread(v_white, 3) / std_white[3] > 1.8);
  CHECK(spread(v_white, 4) / std_white[4] > 1.8);
  CHECK(chi2_gls == Approx(1.0).margin(0.05));
}

TEST_CASE("a refit from the reference linearisation lands where a fresh fit does", "[joint_fit]") {
  // The refit solves J_ref^T r(x) = 0 instead of J(x)^T r(x) = 0: the two differ by the change
  // of J over a draw's few-sigma move times the noise, here (as for the ballbar, um errors on a
  // 100 mm set-up) far below 1e-3 sigma.
  std::mt19937_64 rng(23);
  std::normal_distribution<double> N(0.0, 1.0);
  SineModel m;
  const int n = 200;
  m.t = Eigen::VectorXd::LinSpaced(n, 0.0, 20.0);
  Eigen::VectorXd clean(n);
  for (int i = 0; i < n; ++i) clean[i] = 1.2 * std::sin(0.52 * m.t[i] + 0.25);
  JointFitSettings set;
  set.sigma = 1e-4;
  m.y = clean;
  for (int i = 0; i < n; ++i) m.y[i] += 1e-4 * N(rng);
  const JointFitOutcome ref = solve_joint(m, sine_parameters(), set);
  const JointRefitter refitter(ref, sine_parameters(), set);
  for (int k = 0; k < 5; ++k) {
    m.y = clean;
    for (int i = 0; i < n; ++i) m.y[i] += 1e-4 * N(rng);
    const JointRefitter::Result r = refitter.refit(m);
    const JointFitOutcome fresh = solve_joint(m, sine_parameters(), set);
    CHECK(r.converged);
    CHECK_FALSE(r.fell_back);
    for (int j = 0; j < 5; ++j)
      CHECK(std::abs(r.values[j] - fresh.values[j]) <=
            1e-3 * fresh.estimates[static_cast<std::size_t>(j)].std);
  }
}

TEST_CASE("solve_joint refuses inconsistent input with a message naming it", "[joint_fit]") {
  SineModel m;
  m.t = Eigen::VectorXd::LinSpaced(20, 0.0, 5.0);
  m.y = Eigen::VectorXd::Zero(20);
  JointFitSettings set;
  set.whitener = std::make_shared<Ar1Whitener>(19, 0.5, 1.0);
  CHECK_THROWS_WITH(solve_joint(m, sine_parameters(), set), Catch::Contains("whitener"));
  CHECK_THROWS_WITH(solve_joint(m, {{"A", "mm", 1.0}}), Catch::Contains("parameters"));
  m.y[3] = std::nan("");
  CHECK_THROWS_WITH(solve_joint(m, sine_parameters()), Catch::Contains("residual 3"));
  CHECK_THROWS_AS(solve_joint(m, sine_parameters()), InvalidArgument);
}

TEST_CASE("a long session starts on a subsample and lands on the same solution", "[joint_fit]") {
  struct Subsampled : SineModel {
    bool evaluate_subset(const Eigen::VectorXd& x, Eigen::Index stride, Eigen::VectorXd& r,
                         Eigen::MatrixXd* J) const override {
      SineModel sub;
      const Eigen::Index m = (t.size() + stride - 1) / stride;
      sub.t.resize(m), sub.y.resize(m);
      for (Eigen::Index i = 0; i < m; ++i) sub.t[i] = t[i * stride], sub.y[i] = y[i * stride];
      r.resize(m);
      if (J) J->resize(m, 5);
      sub.evaluate(x, r, J);
      return true;
    }
  };
  std::mt19937_64 rng(29);
  std::normal_distribution<double> N(0.0, 1.0);
  Subsampled m;
  const int n = 20000;
  m.t = Eigen::VectorXd::LinSpaced(n, 0.0, 40.0);
  m.y.resize(n);
  for (int i = 0; i < n; ++i)
    m.y[i] = 1.2 * std::sin(0.52 * m.t[i] + 0.25) + 0.1 - 0.003 * m.t[i] + 1e-3 * N(rng);
  SineModel plain;
  plain.t = m.t, plain.y = m.y;
  JointFitSettings set;
  set.sigma = 1e-3;
  const JointFitOutcome a = solve_joint(m, sine_parameters(), set);
  const JointFitOutcome b = solve_joint(plain, sine_parameters(), set);
  CHECK(a.summary.converged);
  CHECK(a.summary.jacobian_evaluations < b.summary.jacobian_evaluations);
  for (int j = 0; j < 5; ++j) {
    CHECK(std::abs(a.values[j] - b.values[j]) <=
          1e-2 * b.estimates[static_cast<std::size_t>(j)].std);
    CHECK(a.estimates[static_cast<std::size_t>(j)].std ==
          Approx(b.estimates[static_cast<std::size_t>(j)].std).epsilon(1e-3));
  }
}
