#pragma once
/// \file
/// The ballbar test program as a function of time. A transducer samples at its own rate while
/// the machine runs the program, so a recorded sample at time t belongs to the commanded pose
/// at t: the machine axes linearly interpolated between the plan's points, as the control
/// interpolates the G1 blocks of the NC program (nc_program.hpp writes one block per point).
/// One definition, used by the virtual ballbar (to move) and by the recorder (to label rows).

#include <string>
#include <vector>

#include "rotacal/ballbar/test_plan.hpp"
#include "rotacal/io/session.hpp"

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
  /// The session header (machine, L0, nominal pivot) of the program, without samples.
  const BallbarSession& header() const { return header_; }

 private:
  BallbarSession header_;
  std::vector<BallbarSample> points_;
  std::vector<int> segment_;  ///< segment index of each point
};

}  // namespace rotacal
