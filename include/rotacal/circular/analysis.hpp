// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// ISO 230-4 results of ballbar circular tests (circular/plan.hpp) from a `rotacal-ballbar/1`
/// session: per run the circular deviation G, per plane and feed the bidirectional circular
/// deviation G(b) and the circular hysteresis H.
///
/// The actual path of a run is the ballbar's reading placed at the commanded path angle:
///   p_k = (L_k cos theta_k, L_k sin theta_k) in the plane's (u, v) about the nominal pivot.
/// Its centre is that of the least-squares circle (geometric, orthogonal distances:
/// fit/circle.hpp, Hyper fit refined), as ISO 230-4 prescribes; radial deviations are
/// r_k = |p_k - centre| - radius of that circle.
///  - G (per direction): max r - min r, the radial separation of the two concentric circles
///    about the least-squares centre that enclose the path;
///  - G(b): the same for the cw and ccw paths of one plane and feed together, about the
///    least-squares circle of both;
///  - H: the largest |r_ccw(theta) - r_cw(theta)| at the same path angle over the arc both
///    runs cover (r_cw linearly interpolated in theta at the ccw readings), both about the
///    centre of G(b).
///
/// Runs are the session's tests labelled `circular_<plane>_<ccw|cw>[_<suffix>]`; other tests
/// are listed as ignored. Each run is checked: the commanded points lie on the circle of radius
/// L0 about the pivot in the labelled plane (within 1 % of L0) with the rotary axes at 0, the
/// path angle moves monotonically in the labelled direction, and the feed (R |d theta / dt|
/// from a line fit of theta against time) agrees with an `_f<feed>` suffix within 2 %.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rotacal/circular/plan.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// One run's readings, in time order, as the analysis and the diagnosis use them.
struct CircularRunData {
  std::string label;
  CircularPlane plane = CircularPlane::XY;
  CircularDirection direction = CircularDirection::ccw;
  double feed_mm_per_min = 0.0;  ///< from the time and angle columns
  double omega_rad_s = 0.0;      ///< signed d theta / dt (line fit)
  double t0 = 0.0;               ///< intercept of the line fit: theta = theta0 + omega (t - t0)
  double theta0_rad = 0.0;
  std::vector<std::size_t> rows;     ///< session sample indices
  std::vector<double> time;          ///< s
  std::vector<double> theta_rad;     ///< commanded path angle, unwrapped
  std::vector<double> deviation_mm;  ///< reading - L0
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> xyz;  ///< commanded machine axes, mm
  double span_deg() const;
};

/// The circular runs of a session (labels as above, in order of first appearance). Throws
/// InvalidArgument naming the test for a run that fails a check above or has fewer than 36
/// readings, and when the session has no circular run.
std::vector<CircularRunData> circular_runs(const BallbarSession& session);

struct CircularRunResult {
  std::string label;
  CircularPlane plane = CircularPlane::XY;
  CircularDirection direction = CircularDirection::ccw;
  double feed_mm_per_min = 0.0;
  double span_deg = 0.0;
  std::size_t n = 0;
  Eigen::Vector2d centre_um = Eigen::Vector2d::Zero();  ///< LSQ centre - pivot, (u, v), um
  double radius_deviation_um = 0.0;                     ///< LSQ radius - L0, um
  double G_um = 0.0;                                    ///< circular deviation
  double max_um = 0.0, min_um = 0.0;                    ///< largest and smallest radial deviation
  std::vector<double> angle_deg;                        ///< path angle of each reading, in [0, 360)
  std::vector<double> radial_um;  ///< radial deviation of each reading from the LSQ circle
};

struct CircularPairResult {
  CircularPlane plane = CircularPlane::XY;
  double feed_mm_per_min = 0.0;  ///< mean of the two runs'
  std::string ccw_label, cw_label;
  double G_b_um = 0.0;           ///< bidirectional circular deviation
  double H_um = 0.0;             ///< circular hysteresis
  double H_angle_deg = 0.0;      ///< where H is reached, [0, 360)
  double common_span_deg = 0.0;  ///< arc both runs cover
};

struct CircularAnalysis {
  double ballbar_length = 0.0;
  std::vector<CircularRunResult> runs;
  /// One per plane and feed (within 2 %) that has both a ccw and a cw run.
  std::vector<CircularPairResult> pairs;
  std::vector<std::string> ignored_tests;  ///< tests that are not circular runs
};

/// ISO 230-4 results of every circular run and cw/ccw pair. Errors as circular_runs, and
/// DegenerateGeometry from the circle fit.
CircularAnalysis analyze_circular(const BallbarSession& session);

}  // namespace rotacal
