// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The circular-test program (circular/plan.hpp) as a function of time: the counterpart of
/// ProgramTimeline (timeline.hpp) for the ISO 230-4 runs, so that a virtual ballbar can play a
/// circular plan and a recorder can label what it reads with the runs' labels.
///
/// The program, in the plan's time: each run is on its circle from t_start (run-in start, from
/// rest) through the data arc to the overshoot's end at the run's feed; between two runs of a
/// plane the machine moves along the circle, the short way, at the next run's feed, to the next
/// run-in start and dwells 1 s there; between planes it waits `remount_s` at the next plane's
/// first start point while the operator re-mounts the bar (plan_circular_test's time line).
/// Samples on a data arc carry the run's label; every other one is "transition", as the rotary
/// test's timeline labels its transitions (the analysis lists them as ignored tests).

#include <string>
#include <vector>

#include "rotacal/circular/plan.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

class CircularTimeline {
 public:
  /// Where the program is at a time.
  struct Position {
    std::size_t run = 0;     ///< the run being driven, or the next one (transitions)
    bool on_run = false;     ///< on the run's circle at its feed (run-in, data arc or overshoot)
    bool on_data = false;    ///< on its data arc
    bool moving = false;     ///< the axes move (a run, or a move along the circle between runs)
    double angle_deg = 0.0;  ///< commanded path angle in the run's plane
  };

  /// Throws InvalidArgument if the plan has no runs.
  explicit CircularTimeline(CircularPlanResult plan);

  /// Program duration, s: the end of the last run's overshoot.
  double duration() const;
  /// Where the program is at time t (clamped to [0, duration]).
  Position position(double t) const;
  /// Commanded sample at time t (clamped): the run's label on a data arc, else "transition";
  /// X Y Z the commanded machine axes (circular_commanded_session's), rotary axes 0, length L0.
  BallbarSample at(double t) const;
  /// The session header (machine, L0 = radius, pivot = centre), without samples.
  const BallbarSession& header() const { return header_; }
  const CircularPlanResult& plan() const { return plan_; }

 private:
  CircularPlanResult plan_;
  BallbarSession header_;
  std::vector<double> end_;  ///< per run: time at the end of its overshoot, s
};

}  // namespace rotacal
