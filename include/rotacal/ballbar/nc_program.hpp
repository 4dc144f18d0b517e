// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// NC programs of a planned single set-up ballbar test (Flynn et al. 2016, Sec. 3.4).
///
/// Two kinds of program:
/// - `linuxcnc`: machine-axis G-code. X Y Z A|B C are the plan's machine axes, computed by the
///   library's inverse kinematics (nominal, or compensated with identified location errors),
///   so the program needs no 5-axis option: plain G1 blocks, G93 inverse-time feed so every
///   block takes the planned time whatever the mix of linear and rotary motion. Runs on
///   LinuxCNC and, being plain RS274/NGC, on most ISO controllers.
/// - `heidenhain` (conversational, FUNCTION TCPM), `siemens` (TRAORI), `fanuc` (G43.4): the
///   controller's tool-centre-point function moves the machine; coordinates are table-frame
///   (workpiece) positions of the tool-cup ball with the rotary angles. For a compensated plan
///   they are the table-frame points that the NOMINAL kinematics take to the compensated
///   machine axes (the "manipulated NC program" of Flynn Sec. 4).
///
/// Tests and rotary transitions run under TCPM (tool fixed on the table while the table
/// turns). Transitions over the sphere happen at rotary zero with TCPM off (Flynn Sec. 3.4):
/// one circular-interpolation block when the arc lies in a principal plane (G17/G18/G19 G2/G3,
/// Heidenhain CC + C DR+/-), else its planned points as linear blocks. Arc direction: G3 / DR+
/// is a positive rotation about the plane's normal +Z (G17), +Y (G18), +X (G19).
///
/// Workpiece datum of every program: the table frame, origin at the nominal intersection of the
/// rotary axes. Lengths in mm (G21 / G71 / MM), angles in deg.

#include <string>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/io/nc_dialect.hpp"

namespace rotacal {

std::string write_nc_program(const BallbarPlan& plan, NcDialect dialect,
                             const NcProgramOptions& options = {});

}  // namespace rotacal
