// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// In-memory touch-probe session: what a `rotacal-probe/1` file holds
/// (../shared/spec/formats.md, "Touch-probe session"). A calibration sphere is fixed on the
/// table; at each held rotary pose a touch-trigger probe in the spindle approaches it along a
/// few directions aimed at its nominal centre, and the controller latches the stylus-tip centre
/// (the controlled point on a machine with head axes) at each trigger. Values in file units
/// (mm, deg, s) so that write-then-read is exact; accessors convert angles to radians.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/session/session.hpp"

namespace rotacal {

/// One touch.
struct ProbeSample {
  std::string pose;                               ///< label of the held rotary pose ("1", "2", ...)
  double time = 0.0;                              ///< s, non-decreasing
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< latched X, Y, Z, machine frame, mm
  double tilt_deg = 0.0;                          ///< tilt axis (A or B), deg
  double rot_deg = 0.0;                           ///< rotary axis (C), deg
  Eigen::Vector3d n =
      Eigen::Vector3d::UnitZ();    ///< unit direction of the probe's motion, machine frame
  std::vector<std::string> extra;  ///< values of extra columns, as text

  RotaryAngles<double> angles_rad() const {
    return {tilt_deg * M_PI / 180.0, rot_deg * M_PI / 180.0};
  }
};

/// A `rotacal-probe/1` session.
struct ProbeSession {
  MachineType machine = MachineType::AC_trt;
  Eigen::Vector3d sphere = Eigen::Vector3d::Zero();  ///< nominal sphere centre, table frame, mm
  double sphere_diameter = 0.0;                      ///< calibrated, mm
  double stylus_diameter = 0.0;    ///< effective (calibrated, mean pretravel included), mm
  std::optional<double> noise_um;  ///< 1 sigma of each latched coordinate, um
  Metadata metadata;               ///< every `# key: value` line, in order
  std::vector<std::string> extra_columns;
  std::vector<Annotation> annotations;
  std::vector<ProbeSample> samples;
  std::vector<std::string> warnings;  ///< what the reader found suspicious but kept

  /// Distance of the stylus-tip centre from the sphere centre at a trigger of an ideal probe:
  /// (sphere_diameter + stylus_diameter) / 2, mm (formats.md).
  double trigger_radius() const { return 0.5 * (sphere_diameter + stylus_diameter); }
  /// Distinct pose labels in order of first appearance.
  std::vector<std::string> poses() const {
    std::vector<std::string> out;
    for (const ProbeSample& s : samples)
      if (out.empty() || out.back() != s.pose) {
        bool seen = false;
        for (const std::string& p : out) seen = seen || p == s.pose;
        if (!seen) out.push_back(s.pose);
      }
    return out;
  }
  /// Indices of the touches of one pose.
  std::vector<std::size_t> indices_of(const std::string& pose) const {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < samples.size(); ++i)
      if (samples[i].pose == pose) out.push_back(i);
    return out;
  }
};

}  // namespace rotacal
