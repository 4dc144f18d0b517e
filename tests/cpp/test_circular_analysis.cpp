// SPDX-License-Identifier: BSD-3-Clause
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/circular/analysis.hpp"
#include "rotacal/circular/simulate.hpp"
#include "rotacal/core/error.hpp"

using namespace rotacal;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A hand-made run in the XY plane: N evenly spaced commanded angles over the full circle
// (ccw: increasing), reading = radius(theta) from the given function.
template <typename F>
void add_run(BallbarSession& s, const std::string& label, int N, bool ccw, double t0, F reading) {
  for (int k = 0; k < N; ++k) {
    const double th = (ccw ? k : N - 1 - k) * 2.0 * kPi / N;
    BallbarSample b;
    b.test = label;
    b.time = t0 + 0.01 * k;
    b.xyz = s.pivot + s.ballbar_length * Eigen::Vector3d(std::cos(th), std::sin(th), 0.0);
    b.length = reading(th);
    s.samples.push_back(b);
  }
}

BallbarSession empty_session() {
  BallbarSession s;
  s.ballbar_length = 100.0;
  s.pivot = Eigen::Vector3d(120.0, 0.0, 60.0);
  return s;
}

template <typename F>
std::string message_of(F f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  FAIL("no InvalidArgument thrown");
  return {};
}

}  // namespace

TEST_CASE("G of a circle plus a known ellipse is the difference of its semi-axes", "[circular]") {
  // Ellipse with semi-axes A = L0 + 6 um, B = L0 - 4 um, major axis at 30 deg, centred on the
  // pivot, seen with a 7 um centring error along 200 deg (first order: e cos(theta - beta)).
  // ISO 230-4: G = max - min radial deviation about the LSQ centre = A - B = 10 um, whatever
  // the centring, since the LSQ circle takes the centring out (to e^2 / L0 = 5e-10 mm).
  BallbarSession s = empty_session();
  const double L0 = s.ballbar_length, A = L0 + 0.006, B = L0 - 0.004, alpha = 30.0 * kPi / 180.0;
  const double e = 0.007, beta = 200.0 * kPi / 180.0;
  add_run(s, "circular_XY_ccw", 720, true, 0.0, [&](double th) {
    const double c = std::cos(th - alpha), sn = std::sin(th - alpha);
    return A * B / std::sqrt(B * B * c * c + A * A * sn * sn) + e * std::cos(th - beta);
  });
  const CircularAnalysis a = analyze_circular(s);
  REQUIRE(a.runs.size() == 1);
  CHECK(a.runs[0].G_um == Approx(10.0).margin(1e-3));
  CHECK(a.runs[0].centre_um.x() == Approx(7.0 * std::cos(beta)).margin(1e-3));
  CHECK(a.runs[0].centre_um.y() == Approx(7.0 * std::sin(beta)).margin(1e-3));
  CHECK(a.runs[0].span_deg == Approx(359.5));
  CHECK(a.pairs.empty());

  // A perfect circle: G = 0; its radius deviation is the reading's offset.
  BallbarSession c = empty_session();
  add_run(c, "circular_XY_ccw", 360, true, 0.0, [&](double) { return L0 + 0.0025; });
  const CircularAnalysis ac = analyze_circular(c);
  CHECK(ac.runs[0].G_um == Approx(0.0).margin(1e-6));
  CHECK(ac.runs[0].radius_deviation_um == Approx(2.5).margin(1e-6));
}

TEST_CASE("H and G of pure backlash: max(b_u, b_v) from the lost-motion model", "[circular]") {
  // Lost motion: each axis trails by b/2 in its direction of travel. Along the bar, ccw,
  //   dr = (b_X / 2) sgn(sin th) cos th - (b_Y / 2) sgn(cos th) sin th,
  // and cw the opposite. Per quadrant this lies within +-max(b_X, b_Y) / 2, reaching it at the
  // reversals (th = 0, 180 for X; 90, 270 for Y), and ccw - cw = 2 dr: G = G(b) = H =
  // max(b_X, b_Y) (its projections on 1, cos, sin vanish: the LSQ circle is the nominal one).
  const double bX = 0.006, bY = 0.0035;
  CircularTestPlan p;
  p.planes = {CircularPlane::XY};
  p.feeds_mm_per_min = {1000.0};
  p.start_deg = 10.0;  // readings off the reversal points by chance, not by construction
  CircularSimulationOptions o;
  o.errors.backlash = Eigen::Vector3d(bX, bY, 0.02);  // Z does not move in XY
  o.noise_um = 0.0;
  const BallbarSession s = simulate_circular(plan_circular_test(p), o);
  const CircularAnalysis a = analyze_circular(s);
  REQUIRE(a.runs.size() == 2);
  REQUIRE(a.pairs.size() == 1);
  const double expected_um = std::max(bX, bY) * 1e3;
  // Readings are 0.04 deg apart at 1000 mm/min and 250 Hz: the largest sampled |dr| is within
  // (1 - cos 0.04 deg) of the peak, and interpolating the cw run across a step can only lose.
  for (const CircularRunResult& r : a.runs) {
    CHECK(r.G_um == Approx(expected_um).epsilon(1e-3));
    CHECK(std::abs(r.centre_um.norm()) < 1e-3);
  }
  CHECK(a.pairs[0].G_b_um == Approx(expected_um).epsilon(1e-3));
  CHECK(a.pairs[0].H_um == Approx(expected_um).epsilon(2e-3));
  // The largest hysteresis sits at an X reversal (b_X > b_Y).
  const double at = a.pairs[0].H_angle_deg;
  CHECK(std::min({std::abs(at), std::abs(at - 180.0), std::abs(at - 360.0)}) < 1.0);
  CHECK(a.pairs[0].common_span_deg == Approx(360.0).margin(0.1));
}

TEST_CASE("Circular runs: labels, directions and geometry are checked", "[circular]") {
  BallbarSession s = empty_session();
  add_run(s, "circular_XY_ccw", 100, false, 0.0, [](double) { return 100.0; });
  CHECK_THAT(message_of([&] { circular_runs(s); }),
             Catch::Contains("circular_XY_ccw") && Catch::Contains("label says ccw"));

  BallbarSession t = empty_session();
  add_run(t, "circular_YZ_cw", 100, false, 0.0, [](double) { return 100.0; });  // XY points
  CHECK_THAT(message_of([&] { circular_runs(t); }),
             Catch::Contains("circular_YZ_cw") && Catch::Contains("YZ plane"));

  BallbarSession u = empty_session();
  add_run(u, "circular_XZ_cw", 100, false, 0.0, [](double) { return 100.0; });
  CHECK_THAT(message_of([&] { circular_runs(u); }), Catch::Contains("circular_XZ_cw"));

  BallbarSession v = empty_session();
  add_run(v, "radial_C", 100, true, 0.0, [](double) { return 100.0; });
  CHECK_THAT(message_of([&] { circular_runs(v); }), Catch::Contains("no circular run"));

  // A feed in the label that the time column contradicts: 0.01 s per 1 deg at R 100 is
  // 1.745 mm per 0.01 s = 10472 mm/min.
  BallbarSession w = empty_session();
  add_run(w, "circular_XY_ccw_f3000", 360, true, 0.0, [](double) { return 100.0; });
  CHECK_THAT(message_of([&] { circular_runs(w); }), Catch::Contains("f3000"));
  BallbarSession x = empty_session();
  add_run(x, "circular_XY_ccw_f10472", 360, true, 0.0, [](double) { return 100.0; });
  CHECK(circular_runs(x)[0].feed_mm_per_min == Approx(100.0 * (kPi / 180.0) / 0.01 * 60.0));

  // Other tests in the session are listed, not analysed.
  add_run(x, "radial_C", 40, true, 10.0, [](double) { return 100.0; });
  CHECK(analyze_circular(x).ignored_tests == std::vector<std::string>{"radial_C"});
}
