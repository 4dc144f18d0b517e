// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Identification of a thermal R-test session (issue 53; formats.md "Thermal test of a rotary
/// axis", effects.md `thermal_location_R`): one joint fit over every pose of every epoch
/// through the one driver, as probe/thermal.hpp does for the touch probe:
///   r_i = rtest_reading(E0 + sum_l K_l y_l(t_i)) - sum_l Kq_l,N y_l(t_i) + zero_N - d_i
/// with the cold location errors E0, each set-up N's probe zero (one constant over the
/// session: the sensor nest stays mounted through the duty), each lag's gains on every location
/// error and on each nest (table frame: the nest moves, the reading is taken from it), and its
/// tau = 300 s e^q. Nest gains are named q_x, q_y, q_z with one set-up, q_x.N ... with several.

#include "rotacal/io/thermal_file.hpp"
#include "rotacal/session/thermal_result.hpp"

namespace rotacal {

/// Identify a thermal R-test session (InvalidArgument for a duty that turns more than one axis,
/// poses without dx, dy, dz, or too few poses).
ThermalIdentification identify_thermal_rtest(const RtestSession& session,
                                             const ThermalTest& thermal,
                                             const ThermalFitOptions& options = {});

}  // namespace rotacal
