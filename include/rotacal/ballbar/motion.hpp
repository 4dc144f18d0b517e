// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The motion of the rotary axes at each sample of a ballbar session, read from its time and
/// angle columns (issue 16: direction and feed follow from the time and angle columns, so
/// `rotacal-ballbar/1` stays as it is). Input of the motion effects of kinematics/effects.hpp
/// (backlash, servo lag, reversal spikes).

#include <vector>

#include "rotacal/kinematics/machine.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// RotaryMotion of every sample, in session order (rows in time order, as the readers
/// guarantee):
///  - rate: central difference of the commanded angle over time within the run of consecutive
///    rows with the same test label (one-sided at its ends, 0 for a single row), since a test
///    is one continuous move and the rows between tests are not on record;
///  - direction: the sign of the rate, carried over rows at rest (the axis stays on the side of
///    its lost motion it last moved to);
///  - since_reversal: time since the axis last turned round: where the lines through the last
///    row of the old direction and the first of the new, at their rates, meet (the vertex of a
///    program's piecewise-linear path), within those two rows' times.
/// A rate below 1e-9 rad/s counts as rest.
std::vector<RotaryMotion> rotary_motion(const std::vector<BallbarSample>& samples);

}  // namespace rotacal
