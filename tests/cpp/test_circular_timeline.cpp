// SPDX-License-Identifier: BSD-3-Clause
// The circular program as a function of time (circular/timeline.hpp) and the noise-free
// reading a virtual ballbar plays from it (circular/simulate.hpp).
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/circular/simulate.hpp"
#include "rotacal/circular/timeline.hpp"

using namespace rotacal;

namespace {

CircularPlanResult two_planes() {
  CircularTestPlan p;
  p.planes = {CircularPlane::XY, CircularPlane::ZX};
  p.feeds_mm_per_min = {2000.0, 4000.0};
  p.span_deg = 220.0;
  p.start_deg = 30.0;
  p.sample_rate_hz = 50.0;
  p.remount_s = 10.0;
  return plan_circular_test(p);
}

}  // namespace

TEST_CASE("circular timeline: the data arcs' readings get their run's label and commanded point") {
  const CircularPlanResult plan = two_planes();
  const CircularTimeline tl(plan);
  const BallbarSession commanded = circular_commanded_session(plan);
  for (const BallbarSample& s : commanded.samples) {
    const BallbarSample a = tl.at(s.time);
    INFO(s.test << " at " << s.time);
    CHECK(a.test == s.test);
    CHECK((a.xyz - s.xyz).norm() < 1e-9);
    CHECK(a.length == plan.plan.radius);
    CHECK(a.tilt_deg == 0.0);
    CHECK(a.rot_deg == 0.0);
  }
  CHECK(tl.header().ballbar_length == plan.plan.radius);
  CHECK((tl.header().pivot - plan.plan.centre).norm() == 0.0);
}

TEST_CASE("circular timeline: transitions, continuity within a plane, the end") {
  const CircularPlanResult plan = two_planes();
  const CircularTimeline tl(plan);
  const CircularRun& last = plan.runs.back();
  CHECK(tl.duration() ==
        Approx(last.t_start + (last.overshoot_to_deg - last.run_in_from_deg) / last.rate_deg_s));
  // Run-in and overshoot are transitions; so is every instant between two runs.
  for (std::size_t i = 0; i < plan.runs.size(); ++i) {
    const CircularRun& r = plan.runs[i];
    CHECK(tl.at(r.t_start + 0.01).test == "transition");
    CHECK(tl.at(r.time.front()).test == r.label);
    if (i + 1 < plan.runs.size()) {
      const double gap_mid = 0.5 * (r.time.back() + plan.runs[i + 1].time.front());
      CHECK(tl.position(gap_mid).run <= i + 1);
    }
  }
  CHECK(tl.at(-5.0).test == "transition");
  CHECK((tl.at(tl.duration() + 100.0).xyz - tl.at(tl.duration()).xyz).norm() == 0.0);
  // Within a plane the commanded point moves continuously (feed at most 4000 mm/min: less than
  // 0.7 mm per 10 ms); only a remount jumps, to the next plane's start point.
  int jumps = 0;
  const double dt = 0.01;
  for (double t = 0.0; t + dt <= tl.duration(); t += dt) {
    const double step = (tl.at(t + dt).xyz - tl.at(t).xyz).norm();
    if (step > 4000.0 / 60.0 * dt + 1e-6) ++jumps;
  }
  CHECK(jumps == 1);
  // A run's start: the same point the previous position reached after its move and dwell.
  const CircularRun& second = plan.runs[1];
  CHECK((tl.at(second.t_start - 0.5).xyz - tl.at(second.t_start).xyz).norm() < 1e-9);
  CHECK_FALSE(tl.position(second.t_start - 0.5).moving);
  CHECK_THROWS_AS(CircularTimeline(CircularPlanResult{}), InvalidArgument);
}

TEST_CASE("circular exact reading: simulate_circular's readings on the runs, geometry elsewhere") {
  const CircularPlanResult plan = two_planes();
  const CircularTimeline tl(plan);
  CircularSimulationOptions o;
  o.errors.squareness << 40e-6, 0.0, -25e-6;
  o.errors.backlash << 0.003, 0.002, 0.004;
  o.errors.spike << 0.002, 0.0, 0.0;
  o.errors.servo_tau << 0.002, 0.0, 0.001;
  o.errors.cyclic_cos << 0.001, 0.0, 0.0;
  o.centring_error << 0.004, -0.002, 0.001;
  o.length_error = 0.002;
  o.noise_um = 0.0;
  const BallbarSession sim = simulate_circular(plan, o);
  const CircularBar bar(plan.plan, o);
  for (const BallbarSample& s : sim.samples)
    CHECK(circular_exact_reading(tl, bar, s.time) == s.length);
  // At rest between runs: the commanded point with the geometric errors only.
  const CircularRun& second = plan.runs[1];
  const double t = second.t_start - 0.5;
  CircularSimulationOptions geometric_only = o;
  geometric_only.errors.backlash.setZero();
  geometric_only.errors.spike.setZero();
  geometric_only.errors.servo_tau.setZero();
  const CircularBar still(plan.plan, geometric_only);
  CHECK(circular_exact_reading(tl, bar, t) ==
        Approx(still.reading(tl.at(t).xyz)).epsilon(0).margin(1e-12));
  // Options simulate_circular refuses are refused here too, naming the field.
  CircularSimulationOptions bad = o;
  bad.noise_rho = 1.0;
  CHECK_THROWS_WITH(check_circular_simulation(bad), Catch::Contains("noise_rho"));
}
