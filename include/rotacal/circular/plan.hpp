// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// ISO 230-4 circular tests of the linear axes with the ballbar: the plan (plane, centre,
/// radius = bar length, feeds, directions, data arc with run-in and overshoot arcs), its
/// toolpath at the ballbar's sample rate, the commanded `rotacal-ballbar/1` session and the NC
/// program. The same instrument, set-up and files as the rotary-axis test
/// (ballbar/plan.hpp): every rotary axis stays at 0, the pivot ball is the circle's centre.
///
/// Plane axes (u, v) and angle: XY = (X, Y), YZ = (Y, Z), ZX = (Z, X). The path angle theta
/// turns u towards v, so a counter-clockwise (ccw) run is a positive rotation about the plane's
/// normal +Z, +X, +Y: G3 in G17, G19, G18 (the convention of nc_program.hpp).
///   tool-cup ball = centre + R (cos theta e_u + sin theta e_v),  R = L0
///
/// Session labels: `circular_<plane>_<ccw|cw>`, with `_f<feed>` appended when the plan runs
/// more than one feed (`circular_XY_ccw_f1000`). The analysis takes plane and direction from
/// the label and checks them, and the feed, against the time and angle columns; the file
/// format is unchanged (../shared/spec/formats.md: other labels are allowed).
///
/// Units: mm, deg (plan and files), s; feeds mm/min.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "rotacal/io/nc_dialect.hpp"
#include "rotacal/kinematics/machine.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

enum class CircularPlane { XY, YZ, ZX };
/// "XY", "YZ", "ZX".
std::string to_string(CircularPlane plane);
/// Inverse of to_string (also lower case); throws InvalidArgument naming `plane` and the text.
CircularPlane parse_circular_plane(const std::string& text);
/// Indices (0 = X, 1 = Y, 2 = Z) of the plane's u and v axes, and of its normal.
std::array<int, 2> plane_axes(CircularPlane plane);
int plane_normal(CircularPlane plane);

/// ccw: theta increases (G3); cw: theta decreases (G2).
enum class CircularDirection { ccw, cw };
std::string to_string(CircularDirection direction);
/// "ccw" / "cw"; throws InvalidArgument naming `direction` and the text.
CircularDirection parse_circular_direction(const std::string& text);

/// What the operator sets up and the machine runs.
struct CircularTestPlan {
  MachineType machine = MachineType::AC_trt;
  double radius = 100.0;  ///< circle radius = calibrated bar length L0, mm
  /// Centre = nominal pivot ball, table frame at rotary zero (= machine frame there), mm. The
  /// default is the rotary test's pivot (ballbar/plan.hpp), so one set-up serves both tests.
  Eigen::Vector3d centre = Eigen::Vector3d(120.0, 0.0, 60.0);
  std::vector<CircularPlane> planes = {CircularPlane::XY, CircularPlane::YZ, CircularPlane::ZX};
  std::vector<double> feeds_mm_per_min = {1000.0, 3000.0};  ///< path feeds, each run at one
  std::vector<CircularDirection> directions = {CircularDirection::ccw, CircularDirection::cw};
  double start_deg = 0.0;   ///< theta at which the (ccw) data arc starts, deg
  double span_deg = 360.0;  ///< data arc, deg, in (0, 360]; 360 is the full circle
  /// Arcs at the programmed feed before and after the data arc: the axes accelerate and stop
  /// outside it, so the data arc is contoured at constant feed (ISO 230-4 records the path at
  /// the stated feed; a partial arc must exclude the start and stop).
  double run_in_deg = 45.0;
  double overshoot_deg = 45.0;
  double sample_rate_hz = 250.0;  ///< ballbar readings per second
  /// Pause between planes (the operator re-mounts the bar for the next plane), s.
  double remount_s = 30.0;
};

/// One run: one plane, one direction, one feed.
struct CircularRun {
  std::string label;
  CircularPlane plane = CircularPlane::XY;
  CircularDirection direction = CircularDirection::ccw;
  double feed_mm_per_min = 0.0;
  /// Path angles (deg, unwrapped) where the run's run-in starts, the data arc starts and ends,
  /// and the overshoot ends: in the order the machine passes them (decreasing for cw).
  double run_in_from_deg = 0.0, data_from_deg = 0.0, data_to_deg = 0.0, overshoot_to_deg = 0.0;
  double t_start = 0.0;     ///< s: time at run_in_from (the machine starts from rest there)
  double rate_deg_s = 0.0;  ///< signed d theta / dt = +-feed / R, deg/s
  /// Time and path angle of every reading of the data arc, at the sample rate, from the data
  /// arc's start (t = t_start + run-in time) to its end.
  std::vector<double> time;
  std::vector<double> angle_deg;
  /// Path angle (deg) at time t of this run (run-in and overshoot included).
  double angle_at(double t) const;
  double omega_rad_s() const;  ///< signed d theta / dt, rad/s
};

struct CircularPlanResult {
  CircularTestPlan plan;
  std::vector<CircularRun> runs;  ///< planes x feeds x directions, in that nesting order
  std::size_t num_samples() const;
};

/// Label of a run: "circular_XY_ccw", with "_f1000" when `with_feed`.
std::string circular_label(CircularPlane plane, CircularDirection direction, double feed_mm_per_min,
                           bool with_feed);

/// The runs of a plan. Throws InvalidArgument naming the option for: a non-positive or
/// non-finite radius, feed, span, sample rate; a span over 360; negative run-in, overshoot or
/// remount time; no planes, feeds or directions, or a repeated one; feeds that give fewer than
/// 36 readings per data arc or more than 2,000,000 in all.
CircularPlanResult plan_circular_test(const CircularTestPlan& plan);

/// Commanded tool-cup ball centre (mm) of a run at path angle theta (deg).
Eigen::Vector3d circular_point(const CircularTestPlan& plan, CircularPlane plane, double theta_deg);

/// The commanded session: one row per reading of every data arc, labels as above, rotary axes
/// 0, X Y Z the commanded machine axes (the ball, less the tool vector on a head machine),
/// length = L0, pivot = centre, ballbar_length = radius. Input of simulate_circular.
BallbarSession circular_commanded_session(const CircularPlanResult& result);

/// The NC program: per plane, the bar is mounted at the run's start point (M0), then every run
/// of the plane is one continuous path on the circle (run-in, data arc, overshoot, and arcs on
/// the circle to the next run's start) of circular-interpolation blocks of at most 90 deg in
/// G17 / G18 / G19 (heidenhain: CC + C DR+/-), at the run's feed in mm/min (G94). Rotary axes
/// are held at 0; coordinates are machine axes (no TCPM is needed at rotary zero). Uses
/// NcProgramOptions' decimals, tool, stop_to_mount, program_name, program_number.
std::string write_circular_nc_program(const CircularPlanResult& result, NcDialect dialect,
                                      const NcProgramOptions& options = {});

}  // namespace rotacal
