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
