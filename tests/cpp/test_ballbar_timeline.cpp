#include <catch2/catch.hpp>

#include "rotacal/ballbar/timeline.hpp"

using namespace rotacal;

TEST_CASE("the timeline passes through every planned point and labels transitions", "[ballbar]") {
  const BallbarPlan plan = plan_ballbar_test(BallbarSetup{});
  const ProgramTimeline tl(plan);
  CHECK(tl.duration() == Approx(plan.duration()));
  for (const PlanSegment& seg : plan.segments)
    for (const PlannedSample& p : seg.samples) {
      const BallbarSample s = tl.at(p.time);
      CHECK((s.xyz - p.xyz).norm() < 1e-9);
      CHECK(s.tilt_deg == Approx(p.tilt_deg).margin(1e-9));
      CHECK(s.rot_deg == Approx(p.rot_deg).margin(1e-9));
      if (seg.kind == SegmentKind::test) CHECK(s.test == seg.label);
    }
  // Half-way between two points of one test: the mean of the axes, still that test.
  const PlanSegment& first = plan.segments.front();
  const PlannedSample &a = first.samples[10], &b = first.samples[11];
  const BallbarSample mid = tl.at(0.5 * (a.time + b.time));
  CHECK((mid.xyz - 0.5 * (a.xyz + b.xyz)).norm() < 1e-9);
  CHECK(mid.test == first.label);
  // Outside the program: clamped to its ends.
  CHECK((tl.at(-1.0).xyz - first.samples.front().xyz).norm() < 1e-12);
  CHECK((tl.at(1e9).xyz - plan.segments.back().samples.back().xyz).norm() < 1e-12);
}

TEST_CASE("the move from a ccw run into its cw run belongs to the cw run", "[ballbar]") {
  BallbarSetup s;
  s.tests = {BallbarTest::tangential_c, BallbarTest::radial_c};
  s.directions = {SweepDirection::ccw, SweepDirection::cw};
  const BallbarPlan plan = plan_ballbar_test(s);
  const ProgramTimeline tl(plan);
  REQUIRE(plan.segments[0].label == "tangential_C");
  REQUIRE(plan.segments[1].label == "tangential_C_cw");
  const double t_end = plan.segments[0].samples.back().time, t_next = plan.segments[1].samples.front().time;
  const BallbarSample between = tl.at(0.5 * (t_end + t_next));
  CHECK(between.test == "tangential_C_cw");
  CHECK(between.rot_deg == Approx(358.5));
  // Into the next test through an arc: a transition.
  const double t_last = plan.segments[1].samples.back().time;
  CHECK(plan.segments[2].kind == SegmentKind::arc_transition);
  CHECK(tl.at(t_last + 1e-3).test == "transition");
}
