// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The touch probe's candidates for the design engine, shared by the design of a test and the
// separation search (probe/design.hpp): the pose grid within the axis limits that the probing
// program accepts, and the probe problem's Jacobian at the fit's start on nominal touches.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "rotacal/probe/nc_program.hpp"
#include "rotacal/probe/problem.hpp"

namespace rotacal::probe_design {

/// The tilt axis' limits within -90..90 deg (-90..90 without limits), as default_probe_pattern.
std::array<double, 2> tilt_range(MachineType m);

/// The most candidate poses a grid may hold (about 10 kB of design state each).
inline constexpr int kMaxGridPoses = 10000;
/// The grid: tilt over tilt_range every tilt_step (and its end), the rotary axis over a full
/// turn (or its limits, both ends) every rot_step; InvalidArgument naming the steps when it
/// would hold more than kMaxGridPoses poses.
std::vector<RotaryAngles<double>> pose_grid(MachineType m, double tilt_step, double rot_step);

/// Candidate approach directions (machine frame, unit) at a pose (deg): the contact point's
/// normal -n within max_angle_deg of the stylus axis (the spindle's +z turned by the nominal head:
/// the hemisphere the stylus sees, less the shank's margin), at polar angles 0, step, 2 step, ...
/// and max_angle_deg, azimuth every 45 deg in the spindle's frame. On a table machine with the
/// default step and 60 deg among them, the default pattern's five directions are candidates.
std::vector<Eigen::Vector3d> contact_directions(MachineType m, const RotaryAngles<double>& pose_deg,
                                                double max_angle_deg, double step_deg);

/// Poses of the grid (tilt over tilt_range every tilt_step, the rotary axis over a full turn or
/// its limits every rot_step) that probe_moves accepts one by one with P's sphere and
/// directions; the others' reasons in `refused` (when given).
std::vector<RotaryAngles<double>> plannable_poses(MachineType m, const ProbePattern& P,
                                                  double tilt_step, double rot_step,
                                                  const ProbeProgramOptions& program,
                                                  std::vector<std::string>* refused);

/// The commanded touches of P on the nominal machine (no errors, no noise), times from t0.
ProbeSession nominal_touches(MachineType m, const ProbePattern& P, double t0 = 0.0);

/// d residual / d parameter of the probe problem of `session` with effects fx (rows: touches,
/// columns: ProbeParameterLayout), at the fit's start point.
Eigen::MatrixXd start_jacobian(const ProbeSession& session, const EffectModel& fx);

}  // namespace rotacal::probe_design
