// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The segments of the single set-up ballbar test (plan.hpp): the set-up's validation, each
// test's samples, and the moves between tests that keep the ballbar in place. plan.cpp puts
// them in program order and times them.
#include <string>
#include <vector>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/core/angles.hpp"

namespace rotacal::plan_detail {

// Coincidence tolerance for lengths, mm: far below any NC resolution, far above rounding.
inline constexpr double kLengthTol = 1e-9;
// Longest program accepted: a single set-up test runs for minutes to a few hours.
inline constexpr double kMaxProgramSeconds = 24.0 * 3600.0;

void require(bool ok, const std::string& what);
std::string format_number_or_nan(double v);

void validate(const BallbarSetup& s);
PlanSegment make_test(const BallbarSetup& s, BallbarTest t, SweepDirection direction,
                      double feed_factor);
// The moves from the last sample of one test to the first sample of the next, in order; every
// one keeps the tool at L0 from the pivot. The last move stops short of `to`, which is the
// next test's first sample.
std::vector<PlanSegment> transitions(const BallbarSetup& s, const PlannedSample& from,
                                     const PlannedSample& to);

}  // namespace rotacal::plan_detail
