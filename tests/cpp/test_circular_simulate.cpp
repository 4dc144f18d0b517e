// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/circular/simulate.hpp"
#include "rotacal/core/error.hpp"

using namespace rotacal;

namespace {

constexpr double kPi = 3.14159265358979323846;

CircularPlanResult xy_plan(std::vector<double> feeds = {1000.0}) {
  CircularTestPlan p;
  p.planes = {CircularPlane::XY};
  p.feeds_mm_per_min = std::move(feeds);
  return plan_circular_test(p);
}

// Commanded path angle of a sample in the XY plane.
double theta_of(const BallbarSession& s, const BallbarSample& b) {
  return std::atan2(b.xyz.y() - s.pivot.y(), b.xyz.x() - s.pivot.x());
}

}  // namespace

TEST_CASE("Simulated squareness, scale and centring follow their first-order closed forms",
          "[circular]") {
  // x += s y, x += k_X x, y += k_Y y, pivot off by e: along the bar (theta from +X),
  //   dr = s y cos th + k_X x cos th + k_Y y sin th - e . (cos th, sin th)   (+ O(err^2 / R))
  const CircularPlanResult plan = xy_plan();
  CircularSimulationOptions o;
  o.errors.squareness = Eigen::Vector3d(40e-6, 0.0, 0.0);
  o.errors.scale = Eigen::Vector3d(30e-6, -20e-6, 0.0);
  o.centring_error = Eigen::Vector3d(0.004, -0.003, 0.002);
  o.length_error = 0.0015;
  o.noise_um = 0.0;
  const BallbarSession s = simulate_circular(plan, o);
  double worst = 0.0;
  for (const BallbarSample& b : s.samples) {
    const double th = theta_of(s, b), c = std::cos(th), sn = std::sin(th);
    const double x = b.xyz.x(), y = b.xyz.y();
    const double dr =
        40e-6 * y * c + 30e-6 * x * c - 20e-6 * y * sn - (0.004 * c - 0.003 * sn) + 0.0015;
    worst = std::max(worst, std::abs(b.length - s.ballbar_length - dr));
  }
  CHECK(worst < 2e-6);  // second order: (30 um)^2 / 100 mm and the like, 1e-5 um
}

TEST_CASE("Simulated servo mismatch: a 45 deg ellipse whose sign follows the direction",
          "[circular]") {
  // Steady state of first-order loops: x = R cos th + R w tau_X sin th, y = R sin th - R w tau_Y
  // cos th (first order in w tau), so dr = R w (tau_X - tau_Y) sin th cos th.
  const CircularPlanResult plan = xy_plan({3000.0});
  CircularSimulationOptions o;
  o.errors.servo_tau = Eigen::Vector3d(0.0022, 0.0017, 0.0);
  o.noise_um = 0.0;
  const BallbarSession s = simulate_circular(plan, o);
  const double w = 3000.0 / 60.0 / 100.0;  // rad/s
  for (const CircularRun& run : plan.runs) {
    const double sign = run.direction == CircularDirection::ccw ? 1.0 : -1.0;
    double worst = 0.0;
    for (std::size_t i : s.indices_of(run.label)) {
      const BallbarSample& b = s.samples[i];
      const double th = theta_of(s, b);
      // Second order: the radius shrinks by about R (w tau)^2 / 2 = 0.06 um (of a 12.5 um signal).
      const double dr = 100.0 * sign * w * 0.0005 * std::sin(th) * std::cos(th);
      worst = std::max(worst, std::abs(b.length - 100.0 - dr));
    }
    CHECK(worst < 1e-4);
  }
}

TEST_CASE("Simulated reversal spikes decay from the reversal; noise is AR(1) at the sample rate",
          "[circular]") {
  const CircularPlanResult plan = xy_plan();
  CircularSimulationOptions o;
  o.errors.spike = Eigen::Vector3d(0.008, 0.0, 0.0);
  o.errors.spike_tau = Eigen::Vector3d(0.05, 0.05, 0.05);
  o.noise_um = 0.0;
  const BallbarSession s = simulate_circular(plan, o);
  // ccw, just after the X reversal at th = 0: X sticks outward by h e^(-dt/tau), dt = th / w.
  const double w = 1000.0 / 60.0 / 100.0;
  for (const BallbarSample& b : s.samples) {
    if (b.test != "circular_XY_ccw") continue;
    double th = theta_of(s, b);
    if (th > 0.0 && th < 0.2)
      CHECK(b.length - 100.0 ==
            Approx(0.008 * std::exp(-th / w / 0.05) * std::cos(th)).margin(1e-7));
  }

  CircularSimulationOptions n;
  n.noise_um = 0.4;
  n.noise_rho = 0.85;
  n.seed = 7;
  const BallbarSession z = simulate_circular(plan, n);
  // Sample variance and lag-1 correlation of the noise, per run.
  for (const std::string& t : z.tests()) {
    const auto idx = z.indices_of(t);
    double ss = 0.0, lag = 0.0;
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const double e = z.samples[idx[k]].length - 100.0;
      ss += e * e;
      if (k) lag += e * (z.samples[idx[k - 1]].length - 100.0);
    }
    const double sigma_um = std::sqrt(ss / idx.size()) * 1e3;
    CHECK(sigma_um == Approx(0.4).epsilon(0.15));
    CHECK(lag / ss == Approx(0.85).margin(0.03));
  }
  CHECK(*z.noise_um == 0.4);
}

TEST_CASE("Simulation options are checked, naming the field", "[circular]") {
  const CircularPlanResult plan = xy_plan();
  CircularSimulationOptions o;
  o.errors.straightness(0, 0) = 0.001;
  CHECK_THROWS_WITH(simulate_circular(plan, o), Catch::Contains("straightness"));
  o = {};
  o.noise_rho = 1.0;
  CHECK_THROWS_WITH(simulate_circular(plan, o), Catch::Contains("noise_rho"));
  o = {};
  o.errors.screw_pitch.x() = 0.0;
  CHECK_THROWS_WITH(simulate_circular(plan, o), Catch::Contains("screw_pitch"));
  o = {};
  o.errors.backlash.y() = NAN;
  CHECK_THROWS_AS(simulate_circular(plan, o), InvalidArgument);
}
