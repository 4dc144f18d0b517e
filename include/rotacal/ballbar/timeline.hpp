// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The ballbar test program as a function of time. A transducer samples at its own rate while
/// the machine runs the program, so a recorded sample at time t belongs to the commanded pose
/// at t: the machine axes linearly interpolated between the plan's points, as the control
/// interpolates the G1 blocks of the NC program (nc_program.hpp writes one block per point).
/// One definition, used by the virtual ballbar (to move) and by the recorder (to label rows).

#include <string>
#include <vector>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

class ProgramTimeline {
 public:
  /// Every point of the plan, tests and transitions, in program order.
  explicit ProgramTimeline(const BallbarPlan& plan);

  /// Program duration, s.
  double duration() const { return points_.empty() ? 0.0 : points_.back().time; }
  /// Commanded sample at time t (clamped to the program): axes interpolated linearly between
  /// the bracketing points; `test` is their test label if both belong to the same test, the
  /// later one's if its run follows the earlier's with no transition between (the move into
  /// a cw run from the end of its ccw run is that run's first step), otherwise "transition";
  /// `length` is L0.
  BallbarSample at(double t) const;
  /// How the rotary axes move at time t: the rate of the block being run (the axes move
  /// linearly between the points), the direction of the current or last motion, and the time
  /// since the axis last reversed (at the start of the first block of the new direction) -
  /// rotary_motion (ballbar/motion.hpp) for a program instead of recorded rows.
  RotaryMotion motion_at(double t) const;
  /// The session header (machine, L0, nominal pivot) of the program, without samples.
  const BallbarSession& header() const { return header_; }

 private:
  std::size_t bracket(double t) const;  ///< i with points_[i-1].time <= t < points_[i].time

  BallbarSession header_;
  std::vector<BallbarSample> points_;
  std::vector<int> segment_;  ///< segment index of each point
  /// Per block i (from point i-1 to i; entry 0 unused): its rates, the direction of the last
  /// motion up to its end, and when the current direction began after a reversal (NaN: none).
  std::vector<RotaryAngles<double>> block_rate_, block_direction_, block_reversal_;
};

}  // namespace rotacal
