// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Plausibility of a session before any fit: the commanded positions, angles, pivot or nests
/// and the ballbar length L0 must agree through the NOMINAL kinematics (forward() of
/// kinematics/machine.hpp with zero location errors) to within what a machine's errors and a
/// set-up can explain. A session that does not is refused with its likely cause named
/// ("angles look like radians", "lengths look like inches", "all rotary angles equal: the axes
/// never move", "ballbar_length 150 but the data say ~100"), rather than fitted into nonsense.
///
/// Limits (defaults; PlausibilityOptions widens them for an unusual session):
/// - ballbar: every measured length within 2 mm of the nominal distance between the commanded
///   tool ball and the nominal pivot carried by the rotary axes. Location errors of a machine
///   tool are tens of um; a pivot placed by hand is off by well under 1 mm; 2 mm leaves room.
/// - R-test: every commanded sphere centre within 2 mm of the nominal nest carried by the axes,
///   and every displacement within 1 mm (probe ranges are a few mm; machine errors tens of um).
/// - touch probe: every touch's nominal stylus-tip centre within 2 mm (the R-test's position
///   limit: a sphere placed by hand, a machine's errors) of the trigger radius (D + d) / 2
///   from the nominal sphere centre. A misfit names radians, swapped rotary columns, another
///   built-in machine, a trigger radius the data contradict, or the one outlier touch.
/// - ballbar_length at least 20 mm (the shortest ballbars are 50 mm; 100 mm / 25.4 = 3.9).
/// - the rotary axes move: the tilt or the C angle spans at least 1 deg.

#include <string>
#include <vector>

#include "rotacal/session/probe_session.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// Limits of the plausibility checks (mm, deg).
struct PlausibilityOptions {
  double max_length_deviation_mm = 2.0;    ///< ballbar: |measured - nominal length|
  double max_position_deviation_mm = 2.0;  ///< R-test: |commanded centre - nominal nest
                                           ///< position|; probe: |touch distance - radius|
  double max_displacement_mm = 1.0;        ///< R-test: |dx|, |dy|, |dz|
  double min_ballbar_length_mm = 20.0;     ///< L0
  double min_rotary_span_deg = 1.0;        ///< span of the tilt or C angles
};

/// What the checks measured (for a report), when the session passed.
struct PlausibilityReport {
  double median_deviation_mm =
      0.0;  ///< median |measured - nominal| (ballbar) or |xyz - nominal| (R-test)
  double max_deviation_mm = 0.0;  ///< the largest, with the sample it came from
  std::size_t worst_sample = 0;
  double tilt_span_deg = 0.0;
  double rot_span_deg = 0.0;
};

/// Check a ballbar session; throws InvalidArgument naming the likely cause and the sample
/// (index, test label, time) when it is implausible. `source` names the file in messages.
PlausibilityReport check_plausible(const BallbarSession& session, const std::string& source,
                                   const PlausibilityOptions& options = {});
/// Check an R-test session (needs dx, dy, dz for the displacement check; raw-only sessions
/// are checked for their positions alone).
PlausibilityReport check_plausible(const RtestSession& session, const std::string& source,
                                   const PlausibilityOptions& options = {});

/// Check a touch-probe session (rotacal-probe/1): the touches against the nominal sphere.
PlausibilityReport check_plausible(const ProbeSession& session, const std::string& source,
                                   const PlausibilityOptions& options = {});

/// A model applies only to sessions of its machine: throws InvalidArgument
/// "session machine BC-trt, model AC-trt (model.json)" otherwise.
void check_model_machine(MachineType model_machine, MachineType session_machine,
                         const std::string& model_source);

}  // namespace rotacal
