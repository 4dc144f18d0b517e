// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// In-memory measurement sessions: what a `rotacal-ballbar/1` or `rotacal-rtest/1` file holds
/// (../shared/spec/formats.md). Values are kept in file units (mm, deg, s) so that
/// write-then-read is exact; accessors convert angles to radians for the math.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

/// Metadata lines `# key: value`, in file order, unknown keys included (kept, never dropped).
using Metadata = std::vector<std::pair<std::string, std::string>>;

/// A `#` line that stood after the column header (e.g. a recorder's gap marker). It is kept
/// with the index of the sample it precedes, so write-then-read puts it back in place.
struct Annotation {
  std::size_t before_sample = 0;
  std::string text;  ///< the line without its leading '#', trimmed
};

/// One row of a ballbar session.
struct BallbarSample {
  std::string test;                               ///< test label, e.g. "radial_A"
  double time = 0.0;                              ///< s, non-decreasing
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< tool cup, commanded, machine frame, mm
  double tilt_deg = 0.0;                          ///< A or B, deg
  double rot_deg = 0.0;                           ///< C, deg
  double length = 0.0;                            ///< measured centre-to-centre length, mm
  std::vector<std::string> extra;                 ///< values of extra columns, as text

  RotaryAngles<double> angles_rad() const;
};

/// A `rotacal-ballbar/1` session.
struct BallbarSession {
  MachineType machine = MachineType::AC_trt;
  double ballbar_length = 0.0;                      ///< calibrated L0, mm
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();  ///< nominal centre-pivot ball, table frame, mm
  std::optional<double> noise_um;                   ///< 1-sigma noise of one reading, um
  Metadata metadata;                                ///< every `# key: value` line, in order
  std::vector<std::string> extra_columns;           ///< columns beyond the required ones
  std::vector<Annotation> annotations;
  std::vector<BallbarSample> samples;
  /// What the reader found suspicious but kept (e.g. rows repeated exactly); not written back.
  std::vector<std::string> warnings;

  /// Distinct test labels in order of first appearance.
  std::vector<std::string> tests() const;
  /// Indices of the samples of one test.
  std::vector<std::size_t> indices_of(const std::string& test) const;
};

/// One row of an R-test session.
struct RtestSample {
  std::string setup;                              ///< nest label: "N" of `nest.N`
  double time = 0.0;                              ///< s, non-decreasing
  double tilt_deg = 0.0;                          ///< B (or A), deg
  double rot_deg = 0.0;                           ///< C, deg
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< commanded sphere centre, machine frame, mm
  std::optional<Eigen::Vector3d> d;    ///< dx,dy,dz: sphere displacement, table frame, mm
  std::optional<Eigen::Vector3d> raw;  ///< d1,d2,d3: probe readings, mm
  std::vector<std::string> extra;

  RotaryAngles<double> angles_rad() const;
};

/// A `rotacal-rtest/1` session.
struct RtestSession {
  MachineType machine = MachineType::BC_trt;
  std::map<std::string, Eigen::Vector3d>
      nests;  ///< "N" -> nominal ball centre of nest.N, table frame, mm
  std::map<int, Eigen::Vector3d> probe_dirs;  ///< N -> probe.N.dir (unit, table frame)
  std::optional<double> noise_um;
  Metadata metadata;
  std::vector<std::string> extra_columns;
  std::vector<Annotation> annotations;
  std::vector<RtestSample> samples;
  /// What the reader found suspicious but kept (e.g. rows repeated exactly); not written back.
  std::vector<std::string> warnings;

  std::vector<std::string> setups() const;
  std::vector<std::size_t> indices_of(const std::string& setup) const;
};

}  // namespace rotacal
