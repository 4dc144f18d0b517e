// SPDX-License-Identifier: BSD-3-Clause
// The location errors of a thermal model at a lag state or a time of a duty, with their
// covariance (io/thermal_model.hpp), against the closed form of one lag written out here.
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/io/thermal_model.hpp"

using namespace rotacal;

namespace {

// One lag, tau 1800 s; cold errors, gains and their sigmas uncorrelated and known.
ThermalModel one_lag_model() {
  ThermalModel m;
  m.machine = MachineType::AC_trt;
  m.axis = 'C';
  m.tested_speed_rpm = 300.0;
  for (int k = 0; k < 8; ++k) m.cold.v[k] = 0.01 * (k + 1), m.cold_observable[k] = true;
  ThermalModelLag lag;
  lag.tau_s = 1800.0;
  lag.tau_std_s = 30.0;
  for (int k = 0; k < 8; ++k) lag.gains[k] = -0.002 * (k + 1), lag.gain_observable[k] = true;
  m.lags.push_back(lag);
  m.test_heat.start = {0.0, 7200.0};
  m.test_heat.u = {3.0, 0.0};
  m.covariance = Eigen::MatrixXd::Zero(17, 17);
  for (int k = 0; k < 8; ++k) {
    m.covariance(k, k) = 1e-8 * (k + 1);          // cold
    m.covariance(9 + k, 9 + k) = 4e-9 * (k + 1);  // gains
  }
  m.covariance(8, 8) = 30.0 * 30.0;  // tau, s^2
  return m;
}

}  // namespace

TEST_CASE("thermal model: errors at a time of the duty are E0 + K y(t), tau's sigma propagated") {
  const ThermalModel m = one_lag_model();
  const double tau = 1800.0;
  for (double t : {0.0, 600.0, 3600.0, 7200.0, 9000.0}) {
    // The lag written out: u = 3 until 7200 s, then 0.
    const double y7200 = 3.0 * (1.0 - std::exp(-7200.0 / tau));
    const double y =
        t <= 7200.0 ? 3.0 * (1.0 - std::exp(-t / tau)) : y7200 * std::exp(-(t - 7200.0) / tau);
    const double dy = t <= 7200.0
                          ? -3.0 * t / (tau * tau) * std::exp(-t / tau)
                          : y7200 * (t - 7200.0) / (tau * tau) * std::exp(-(t - 7200.0) / tau) -
                                3.0 * 7200.0 / (tau * tau) * std::exp(-7200.0 / tau) *
                                    std::exp(-(t - 7200.0) / tau);
    const ThermalErrorsAt e = thermal_errors_at_time(m, m.test_heat, t);
    REQUIRE(e.y.size() == 1);
    CHECK(e.y[0] == Approx(y).margin(1e-15));
    for (int k = 0; k < 8; ++k) {
      const double K = -0.002 * (k + 1);
      CHECK(e.errors.v[k] == Approx(0.01 * (k + 1) + K * y).epsilon(1e-12));
      const double var = 1e-8 * (k + 1) + y * y * 4e-9 * (k + 1) + K * K * dy * dy * 900.0;
      CHECK(e.covariance(k, k) == Approx(var).epsilon(1e-9));
      CHECK(e.observable[static_cast<std::size_t>(k)]);
    }
    // Errors share tau: their covariance is K_a K_b (dy/dtau)^2 var(tau).
    CHECK(e.covariance(0, 1) == Approx(0.002 * 0.004 * dy * dy * 900.0).margin(1e-20));
  }
}

TEST_CASE("thermal model: a given state is exact, and refused when it is not a state") {
  ThermalModel m = one_lag_model();
  const ThermalErrorsAt e = thermal_errors_at_state(m, {1.5});
  for (int k = 0; k < 8; ++k) {
    CHECK(e.errors.v[k] == Approx(0.01 * (k + 1) - 0.002 * (k + 1) * 1.5).epsilon(1e-12));
    CHECK(e.covariance(k, k) == Approx(1e-8 * (k + 1) + 2.25 * 4e-9 * (k + 1)).epsilon(1e-12));
  }
  CHECK_THROWS_WITH(thermal_errors_at_state(m, {1.0, 2.0}),
                    Catch::Contains("1 lag(s), 2 state(s)"));
  CHECK_THROWS_AS(thermal_errors_at_state(m, {-0.1}), InvalidArgument);
  CHECK_THROWS_AS(thermal_errors_at_state(m, {NAN}), InvalidArgument);
  // A gain the test did not determine leaves the drifted error undetermined, not cold.
  m.lags[0].gain_observable[2] = false;
  CHECK_FALSE(thermal_errors_at_state(m, {1.0}).observable[2]);
  CHECK(thermal_errors_at_state(m, {0.0}).observable[2]);
}
