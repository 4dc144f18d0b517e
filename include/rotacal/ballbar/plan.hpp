// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Toolpath of the single set-up ballbar test (Flynn et al. 2016, Sec. 3): three sphere arcs at
/// rotary zero that locate the centre pivot (Sec. 3.1), radial and axial tests of both rotary
/// axes from that ONE pivot position (Secs. 3.2, 3.3), and transitions between the tests that
/// keep the ball-to-ball distance at L0 so the ballbar stays in place (Sec. 3.4).
///
/// Every tool position is planned in the table frame first (where the pivot is fixed); the
/// machine axes come from `inverse()` of kinematics/machine.hpp, i.e. Flynn Eq. 1 as a rotation
/// of the table-frame point about the axis lines. With no location errors this is the nominal
/// TCPM transform; with identified errors it is the compensated program.
///
/// Units: mm, and degrees for angles stored in the plan (they are what the NC program and the
/// session files carry); `angles_rad()` converts for the kinematics.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/kinematics/machine.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// The tests of the single set-up method. `radial_tilt` / `axial_tilt` are labelled radial_A /
/// axial_A on an AC-trt machine and radial_B / axial_B on a BC-trt machine. The tangential
/// tests (issue 16) put the bar along the circle the pivot follows, so they read the axis'
/// angle itself (positioning, backlash, servo lag), which radial and axial tests see only to
/// second order; they are planned for table axes.
enum class BallbarTest {
  sphere_xy,
  sphere_yz,
  sphere_zx,
  radial_tilt,
  axial_tilt,
  radial_c,
  axial_c,
  tangential_tilt,
  tangential_c
};

/// True for the tests that sweep a rotary axis (every test but the three sphere arcs).
bool is_rotary_test(BallbarTest test);

/// Session label of a test on a machine: "sphere_xy", ..., "radial_A" or "radial_B", "axial_C",
/// "tangential_C".
std::string test_label(BallbarTest test, MachineType machine);
/// Inverse of test_label; throws InvalidArgument naming the label and the labels known for the
/// machine (e.g. "radial_B" on an AC-trt machine is refused).
BallbarTest parse_ballbar_test(const std::string& label, MachineType machine);
/// The order of the reference sessions in shared/data: sphere_xy, sphere_yz, sphere_zx,
/// radial tilt, axial C, radial C, axial tilt.
std::vector<BallbarTest> default_ballbar_tests();

/// Direction of a rotary test's sweep. `ccw` turns the axis towards increasing angles (a
/// right-handed, counter-clockwise turn about the axis direction, as G3 is for a circle);
/// `cw` back. A ccw run keeps the test's label, a cw run appends "_cw" (radial_C_cw).
enum class SweepDirection { ccw, cw };
std::string to_string(SweepDirection d);
/// "ccw" / "cw"; throws InvalidArgument otherwise.
SweepDirection parse_sweep_direction(const std::string& text);

/// The '±' of Flynn's radial C test (Sec. 3.2): the tool-cup circle is outside (+L0, larger
/// radius than the pivot circle) or inside (-L0) the circle the pivot follows.
enum class RadialSide { outside, inside };
std::string to_string(RadialSide side);
/// "outside" / "inside" (also "+" / "-"); throws InvalidArgument otherwise.
RadialSide parse_radial_side(const std::string& text);

/// Options of the test layout. Defaults reproduce shared/data/ballbar_ac_table2.csv.
struct BallbarSetup {
  MachineType machine = MachineType::AC_trt;
  double ballbar_length = 100.0;  ///< calibrated centre-to-centre length L0, mm
  /// Nominal centre of the pivot ball, table frame, mm. Flynn's O_x is its distance from the C
  /// axis, O_z its height above the tilt axis.
  Eigen::Vector3d pivot = Eigen::Vector3d(120.0, 0.0, 60.0);
  /// Tilt-axis (A or B) sweep of radial_tilt / axial_tilt, deg, inclusive.
  std::array<double, 2> tilt_range_deg = {-90.0, 90.0};
  /// C sweep of radial_c / axial_c, deg. A span of exactly 360 is a full turn whose end pose
  /// repeats the start, so the end sample is left out (0..359 at 1 deg); otherwise inclusive.
  std::array<double, 2> rot_range_deg = {0.0, 360.0};
  /// Sample spacing of every test and of the sampled transitions, deg (rotary angle or angle
  /// about the pivot). A range whose end is off this grid gets the end as a last sample.
  double step_deg = 1.0;
  double feed_mm_per_min = 1000.0;   ///< linear axes (machine X, Y, Z path), mm/min
  double feed_deg_per_min = 3600.0;  ///< rotary axes, deg/min
  std::vector<BallbarTest> tests = default_ballbar_tests();  ///< tests to run, in this order
  /// Directions every rotary test runs in, one run each, in this order; a cw run right after
  /// the ccw one starts where it ended, so the axis reverses there.
  std::vector<SweepDirection> directions = {SweepDirection::ccw};
  /// Feeds every rotary test runs at, as factors of feed_mm_per_min and feed_deg_per_min; the
  /// first must be 1. A run at factor k != 1 appends "_f<feed_mm_per_min * k>" to its label
  /// (radial_C_cw_f2000). Two feeds tell servo lag (proportional to the speed) from backlash.
  std::vector<double> feed_factors = {1.0};
  RadialSide radial_c_side = RadialSide::outside;  ///< Flynn's '±' of radial C
  /// Tilt angle (deg) held during axial_c. Unset: 0, except on a head-head machine, where the
  /// ball sits on the rotary (C) head axis at tilt 0 and its position and tilt errors are seen
  /// only as one combination per ball height; 45 deg takes the ball off the axis, where the
  /// axial bar reads the C tilt alone (default_axial_c_tilt_deg).
  std::optional<double> axial_c_tilt_deg;
};

/// The default tilt sweep of a machine: -90..90 deg, within the tilt axis' limits (0..90 on
/// the nutating B45C-trt, whose B turns 0..180).
std::array<double, 2> default_tilt_range_deg(MachineType machine);

/// The tilt held during axial_c when BallbarSetup::axial_c_tilt_deg is unset.
double default_axial_c_tilt_deg(MachineType machine);

/// One commanded point of the toolpath.
struct PlannedSample {
  double time = 0.0;  ///< s since the first sample, at the setup's feeds
  Eigen::Vector3d p_table = Eigen::Vector3d::Zero();  ///< tool-cup ball centre, table frame, mm
  double tilt_deg = 0.0;                              ///< A or B, deg
  double rot_deg = 0.0;                               ///< C, deg (absolute, not wrapped)
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();      ///< machine axes X, Y, Z, mm

  RotaryAngles<double> angles_rad() const;
};

enum class SegmentKind {
  test,               ///< one ballbar test: every sample is a measurement point
  rotary_transition,  ///< rotary axes move, tool fixed on the table (ballbar rides along)
  arc_transition,     ///< great-circle arc about the pivot at rotary zero (TCPM off in NC)
};

/// A great-circle arc on the sphere of radius L0 about the pivot, at all rotary axes 0 where
/// the machine frame and the table frame coincide (for any location errors: rotations by 0).
struct TransitionArc {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();   ///< table frame = machine frame, mm
  Eigen::Vector3d end = Eigen::Vector3d::Zero();     ///< table frame = machine frame, mm
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< the nominal pivot, mm
  Eigen::Vector3d axis =
      Eigen::Vector3d::UnitZ();  ///< unit; start turns positively about it to end
  double angle = 0.0;            ///< rad, in (0, pi]
  /// If `axis` is +-X, +-Y or +-Z: that index (0: YZ plane, G19; 1: ZX plane, G18; 2: XY plane,
  /// G17), so the arc can be one circular-interpolation block. -1 otherwise.
  int principal_axis = -1;
};

/// A run of samples of one kind. A transition holds the points strictly between the previous
/// segment's last sample and the next test's first sample (the tool moves from one to the
/// other through them); an arc transition may hold none and is then the arc alone.
struct PlanSegment {
  std::string label;  ///< run label (run_label) or "transition"
  SegmentKind kind = SegmentKind::test;
  std::optional<BallbarTest> test;                 ///< set for kind == test
  SweepDirection direction = SweepDirection::ccw;  ///< of a rotary test
  double feed_factor = 1.0;                        ///< of the feeds during this segment
  TransitionArc arc;                               ///< meaningful for kind == arc_transition
  std::vector<PlannedSample> samples;
};

struct BallbarPlan {
  BallbarSetup setup;
  /// Location errors the machine axes were computed with (compensated program); empty for the
  /// nominal program. Order and units of LocationErrors.
  std::optional<LocationErrors<double>> compensation;
  std::vector<PlanSegment> segments;

  std::size_t num_samples() const;
  /// Time of the last sample, s.
  double duration() const;
};

/// Label of one run of a test: test_label, then "_cw" for a cw run and "_f<feed>" for a feed
/// factor other than 1 (feed = feed_mm_per_min * factor, as %g).
std::string run_label(BallbarTest test, SweepDirection direction, double feed_factor,
                      const BallbarSetup& setup);

/// The test label of a run label: run_label without its "_cw" and "_f<feed>" suffixes
/// ("radial_C_cw_f2000" -> "radial_C"); any other label unchanged.
std::string test_of_run(const std::string& label);

/// Plan the single set-up ballbar test.
///
/// Tests (p = pivot, L = L0, t over the sweep):
///   sphere_xy  p + L (cos t, sin t, 0), t full turn;    sphere_yz  p + L (0, cos t, sin t),
///   sphere_zx  p + L (cos t, 0, sin t), t in [0, 180];  all at rotary zero (Sec. 3.1);
///   radial_tilt  tool at p + L r, r = unit vector from the tilt axis to p (Flynn: z = L0),
///   axial_tilt   tool at p + L a, a = tilt-axis direction (+X for A, +Y for B),
///   radial_c     tool at p +- L r, r = unit vector from the C axis to p (Flynn: x = +-L0),
///   axial_c      tool at p + L (0, 0, 1);
///   tangential_tilt / tangential_c  tool at p + L (a x r), a the axis direction, r as radial;
/// each fixed on the table while the axis sweeps (the machine moves it by Flynn Eq. 1).
/// Each rotary test runs once per feed factor and, within that, once per direction.
/// Between tests the tool goes, with |tool - pivot| = L0 throughout: rotary axes to 0 with the
/// tool fixed on the table, a great-circle arc about the pivot (shortest, over the top when
/// the ends are opposite), rotary axes to the next start with the tool fixed on the table;
/// only the moves that are needed. The plan starts at the first test's first sample.
///
/// `identified`: location errors used for the machine axes (compensated program); none gives
/// the nominal TCPM toolpath. Times are cumulative:
///   dt = 60 max(|dXYZ| / feed_mm_per_min, max(|dA|, |dC|) / feed_deg_per_min).
/// Throws InvalidArgument naming the option for a non-positive or non-finite length, step or
/// feed, an empty or reversed range, a span over 360 deg, no or repeated tests, a pivot on the
/// axis that a radial test turns about, or non-finite errors.
BallbarPlan plan_ballbar_test(
    const BallbarSetup& setup,
    const std::optional<LocationErrors<double>>& identified = std::nullopt);

/// The plan as flat arrays, one row per sample in program order (for bindings and tools).
struct PlanTable {
  std::vector<std::string> labels;  ///< segment label of each sample
  std::vector<int> segment;         ///< index into plan.segments
  Eigen::VectorXd time;             ///< s
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> p_table;     ///< mm, table frame
  Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> angles_deg;  ///< tilt, C; deg
  Eigen::Matrix<double, Eigen::Dynamic, 5, Eigen::RowMajor>
      machine_axes;  ///< X,Y,Z mm; tilt, C deg
};
PlanTable tabulate(const BallbarPlan& plan);

/// The commanded session of the plan's test samples (transitions left out): test labels, time,
/// X,Y,Z, angles, machine, L0 and pivot; `length` is set to L0. Input of simulate_ballbar.
BallbarSession commanded_session(const BallbarPlan& plan);

}  // namespace rotacal
