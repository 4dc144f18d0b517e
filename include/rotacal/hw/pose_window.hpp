// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// When an R-test pose is read: the timing the recorder and the virtual R-test agree on
/// (docs/protocols.md, "When a pose is read").
///
/// Pose k is commanded at program time t_k (the program's `time` column, one dwell D apart).
/// The program moves the table in the D/10 before and after each pose time's window and holds
/// it at rest for the middle 80 % of the dwell: the pose's read window [t_k - 0.4 D, t_k + 0.4 D]
/// (the first pose is held from the start, the last until the program ends). A reading counts
/// for pose k only if the whole interval in which it may have been taken lies in that window;
/// its margin is the distance from that interval to the nearer edge of the window.

#include <algorithm>
#include <string>

namespace rotacal::hw {

/// Fraction of each dwell during which the table is at rest, centred on the pose time.
inline constexpr double kRtestRestFraction = 0.8;

/// A pose's read window, program time, s.
struct PoseWindow {
  double begin = 0.0;
  double end = 0.0;
  /// Whether a reading taken somewhere in [a, b] was surely taken at rest.
  bool contains(double a, double b) const { return a >= begin && b <= end; }
  /// Distance of [a, b] from the nearer edge, s: positive inside, negative across an edge.
  double margin(double a, double b) const { return std::min(a - begin, end - b); }
};

/// The read window of the pose commanded at `t_pose` in a program with dwell `dwell_s`.
inline PoseWindow pose_window(double t_pose, double dwell_s) {
  const double half = 0.5 * kRtestRestFraction * dwell_s;
  return {t_pose - half, t_pose + half};
}

}  // namespace rotacal::hw
