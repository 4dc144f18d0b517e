// core/fit_with_noise.hpp: a white fit, the noise model of its residuals and, when that is
// correlated, the GLS refit whose sigma holds on correlated data (checked over draws).
#include <catch2/catch.hpp>

#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/noise_model.hpp"

using namespace rotacal;

namespace {
// y_i = a + b t_i / T (mm) with measurements y.
class Line : public ResidualModel {
 public:
  Line(Eigen::VectorXd t, Eigen::VectorXd y) : t_(std::move(t)), y_(std::move(y)) {}
  Eigen::Index num_residuals() const override { return t_.size(); }
  int num_parameters() const override { return 2; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r, Eigen::MatrixXd* J) const override {
    const double T = t_[t_.size() - 1];
    r = (x[0] + x[1] * t_.array() / T).matrix() - y_;
    if (J) J->col(0).setOnes(), J->col(1) = t_ / T;
  }

 private:
  Eigen::VectorXd t_, y_;
};

struct Draw {
  NoiseFitOutcome fit;
  double a_error;
};

Draw draw(double rho, std::uint64_t seed) {
  const int n = 400;
  std::vector<std::string> groups(n, "stream");
  std::vector<double> times(n);
  Eigen::VectorXd t(n);
  for (int i = 0; i < n; ++i) times[static_cast<std::size_t>(i)] = t[i] = i;
  const Eigen::VectorXd e = noise_gen::ar1(groups, times, rho, 1e-3, seed);
  const Line model(t, (0.01 + 0.002 * t.array() / (n - 1)).matrix() + e);
  const std::vector<FitParameter> params = {{"a", "mm", 0.0}, {"b", "mm", 0.0}};
  JointFitSettings s;
  s.sigma = 1e-3;
  Draw d{fit_with_noise(model, params, s, groups, times), 0.0};
  d.a_error = d.fit.fit.values[0] - 0.01;
  return d;
}
}  // namespace

TEST_CASE("correlated noise is refitted by GLS and its sigma holds over draws", "[noise]") {
  double chi2_gls = 0.0, chi2_white = 0.0;
  const int draws = 40;
  for (int k = 0; k < draws; ++k) {
    const Draw d = draw(0.9, 10 + static_cast<std::uint64_t>(k));
    REQUIRE(d.fit.refit);
    CHECK_FALSE(d.fit.note.empty());
    CHECK(d.fit.correction >= 1.0);
    chi2_gls += std::pow(d.a_error / d.fit.fit.estimates[0].std, 2) / draws;
    // The white sigma of the same data: sqrt(s^2 (J^T J)^-1) ~ 1.6 um / sqrt(400) for a.
    chi2_white += std::pow(d.a_error / (1e-3 * std::sqrt(4.0 / 400.0)), 2) / draws;
  }
  // A mean of 40 squared z-scores: 1 +- 0.22 for a correct sigma; the white one is ~4x too small.
  CHECK(chi2_gls > 0.45);
  CHECK(chi2_gls < 1.8);
  CHECK(chi2_white > 5.0);
}

TEST_CASE("white noise is fitted once, and sizes are checked", "[noise]") {
  const Draw d = draw(0.0, 3);
  CHECK_FALSE(d.fit.refit);
  CHECK(d.fit.note.empty());
  CHECK(d.fit.noise.n == 400);
  const Line model(Eigen::VectorXd::LinSpaced(10, 0, 9), Eigen::VectorXd::Zero(10));
  CHECK_THROWS_AS(fit_with_noise(model, {{"a", "mm", 0.0}, {"b", "mm", 0.0}}, JointFitSettings{},
                                 std::vector<std::string>(9, "g"), std::vector<double>(10, 0.0)),
                  InvalidArgument);
}
