// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/ballbar/motion.hpp"
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
  const double t_end = plan.segments[0].samples.back().time,
               t_next = plan.segments[1].samples.front().time;
  const BallbarSample between = tl.at(0.5 * (t_end + t_next));
  CHECK(between.test == "tangential_C_cw");
  CHECK(between.rot_deg == Approx(358.5));
  // Into the next test through an arc: a transition.
  const double t_last = plan.segments[1].samples.back().time;
  CHECK(plan.segments[2].kind == SegmentKind::arc_transition);
  CHECK(tl.at(t_last + 1e-3).test == "transition");
}

TEST_CASE("the program's motion agrees with the motion read back from its recorded rows",
          "[ballbar][motion]") {
  // What the virtual ballbar plays (motion_at) and what the fit reads from the file
  // (rotary_motion of the rows) must be the same motion, or a recorded backlash would be
  // fitted against a different signature than the one played.
  BallbarSetup s;
  s.tests = {BallbarTest::radial_c, BallbarTest::tangential_c, BallbarTest::radial_tilt};
  s.directions = {SweepDirection::ccw, SweepDirection::cw};
  s.feed_factors = {1.0, 2.0};
  s.step_deg = 5.0;
  const ProgramTimeline tl(plan_ballbar_test(s));
  std::vector<BallbarSample> rows;  // as the recorder writes them, transitions included
  for (double t = 0.0; t <= tl.duration(); t += 0.01) rows.push_back(tl.at(t));
  const std::vector<RotaryMotion> read = rotary_motion(rows);
  int compared = 0, reversals = 0;
  for (std::size_t i = 1; i + 1 < rows.size(); ++i) {
    // Test rows away from the ends of a run, where the rows' one-sided differences see one
    // block only (a transition's blocks change speed within its rows).
    if (rows[i].test == "transition") continue;
    if (rows[i - 1].test != rows[i].test || rows[i + 1].test != rows[i].test) continue;
    const RotaryMotion played = tl.motion_at(rows[i].time);
    INFO(rows[i].test << " at t = " << rows[i].time);
    CHECK(played.direction.rot == read[i].direction.rot);
    CHECK(played.direction.tilt == read[i].direction.tilt);
    CHECK(played.rate.rot == Approx(read[i].rate.rot).margin(1e-9));
    CHECK(played.rate.tilt == Approx(read[i].rate.tilt).margin(1e-9));
    // The rows place a reversal where the lines through the rows on either side meet: at
    // the program's vertex.
    CHECK(std::isfinite(played.since_reversal.rot) == std::isfinite(read[i].since_reversal.rot));
    CHECK(std::isfinite(played.since_reversal.tilt) == std::isfinite(read[i].since_reversal.tilt));
    if (std::isfinite(played.since_reversal.rot) && std::isfinite(read[i].since_reversal.rot)) {
      ++reversals;
      CHECK(played.since_reversal.rot == Approx(read[i].since_reversal.rot).margin(1e-6));
    }
    if (std::isfinite(played.since_reversal.tilt) && std::isfinite(read[i].since_reversal.tilt))
      CHECK(played.since_reversal.tilt == Approx(read[i].since_reversal.tilt).margin(1e-6));
    ++compared;
  }
  CHECK(compared > 1000);
  CHECK(reversals > 100);
}
