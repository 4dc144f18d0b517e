// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The probing program of a touch-probe session (issue 31, item 1: `rotacal plan probe`), and
/// the reader of what it logs.
///
/// Geometry (the simulator's, probe/simulate.hpp): at each pose of the pattern, held at rest,
/// the stylus tip starts on the line through the sphere's nominal centre c (placed in machine
/// axes by the nominal machine) along the approach direction n (machine frame), at
/// c - (r + approach) n, r = (D + d)/2 the calibrated trigger radius, and probes towards
/// c - (r - overtravel) n. It retracts to the start along the same line, then straight up to
/// the retract plane. Between poses the rotary axes turn with the tool on the retract plane,
/// above the sphere at every pose and all along the turns between them (the program starts by
/// going up to it before the first turn). A move that would pass through the sphere (closer than r
/// to its nominal centre), a rotary angle outside the machine's limits or a linear position outside
/// its travel (when the description gives it) is refused.
///
/// Dialects: linuxcnc only, machine axes: `G38.2` per touch, and the latched position #5061
/// #5062 #5063 written to a log file with `(LOGOPEN,file)`, `(LOG,...)`, `(LOGCLOSE)`; every
/// other dialect is refused (no probing words of it are implemented that can be checked here).

#include <optional>
#include <string>
#include <vector>

#include "rotacal/io/nc_dialect.hpp"
#include "rotacal/probe/simulate.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

/// The duty of a thermal test's program (formats.md "Thermal test of a rotary axis"): the
/// pattern as one epoch at 0 s and every interval_s (each taking pose_dt_s per pose, the
/// template's clock), `axis` turning at speed_rpm between epochs until heat_s, then at rest
/// (G4) to heat_s + cool_s. An endless axis turns whole revolutions, half of them back, so its
/// position stays bounded; the tilting axis (or any axis with limits) swings between the pattern's
/// lowest and highest angle of it, at a mean absolute speed of speed_rpm.
struct ThermalProgramDuty {
  char axis = 'C';
  double speed_rpm = 300.0;      ///< rev/min while heating
  double heat_s = 14400.0;       ///< s
  double cool_s = 7200.0;        ///< s
  double interval_s = 600.0;     ///< s, from one epoch's start to the next's
  double max_speed_rpm = 500.0;  ///< the axis' speed limit: speed_rpm above it is refused
  /// Epoch start times, s (0, interval_s, ... up to heat_s + cool_s).
  std::vector<double> epoch_starts() const;
};

struct ProbeProgramOptions {
  int decimals = 4;            ///< digits after the point, 0..9
  int tool = 1;                ///< G43 H<tool> on a table machine; 0 leaves it to the operator
  double approach_mm = 5.0;    ///< start of a probing move: this far outside the trigger sphere
  double overtravel_mm = 2.0;  ///< its G38.2 target: this far inside it
  double clearance_mm = 20.0;  ///< retract plane: this far above the highest trigger sphere top
  double probe_feed_mm_per_min = 50.0;
  double feed_mm_per_min = 1000.0;             ///< positioning feed between touches (G1)
  std::string log_file = "rotacal_probe.log";  ///< the controller's file of the latched positions
  /// A thermal test: the pattern once per epoch (pose numbers run on), the duty between.
  std::optional<ThermalProgramDuty> thermal;
};

/// The longest --log-file name: "(LOGOPEN," + name + ")" within LinuxCNC's 254-character line.
inline constexpr std::size_t kMaxLogFileName = 254 - 10;

/// One probing move, machine axes (mm, deg).
struct ProbeMove {
  int pose = 1;   ///< 1-based pose number
  int touch = 1;  ///< 1-based touch number within the pose
  RotaryAngles<double> angles_deg;
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  ///< approach direction, machine frame, unit
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

/// The probing moves of pattern P on machine m, with the retract plane's Z (mm) in `retract_z`.
/// Throws InvalidArgument for an empty pattern, a zero direction, options out of range (non
/// positive approach, overtravel or feeds, overtravel >= the trigger radius), a rotary angle
/// outside the machine's limits, a move outside its travel, or a move through the sphere.
std::vector<ProbeMove> probe_moves(MachineType m, const ProbePattern& P,
                                   const ProbeProgramOptions& o, double* retract_z = nullptr);

/// The NC program of the probing moves (lines end with '\n'). InvalidArgument as probe_moves,
/// for a dialect other than linuxcnc, naming it, and for a thermal duty whose speed exceeds
/// its max_speed_rpm, whose axis the machine lacks, or whose interval does not hold an epoch.
std::string write_probe_nc_program(MachineType m, const ProbePattern& P, NcDialect dialect,
                                   const ProbeProgramOptions& options = {});

/// The session of a LinuxCNC log written by that program: its lines "pose touch X Y Z" (the
/// latched #5061..#5063) take the place of the X, Y, Z of `plan`'s rows, in order (the plan:
/// the session template of the same pattern, its rows in probe_moves order). Throws ParseError
/// naming `path` and the line for a line that is not five numbers, a pose or touch number out
/// of order, a row count that differs from the plan's, or a latched position farther than
/// `max_off_line_mm` from its commanded line (the plan's X, Y, Z along its approach direction:
/// G38.2 moves on that line, so a latch off it by more than a servo's error is not the touch
/// commanded); IoError if the file cannot be read.
ProbeSession read_linuxcnc_probe_log(const std::string& path, const ProbeSession& plan,
                                     double max_off_line_mm = 1.0);

}  // namespace rotacal
