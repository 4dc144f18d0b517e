// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Whether two effects can be told apart by any instrument at all, from the motion of the
/// table they cause (the design engine's first question, before any added test is searched).

#include <array>
#include <string>

#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

/// Whether two effects can be told apart by any instrument at all, decided from the motion of
/// the table they cause. Every instrument of the library reads the table through points fixed
/// on it (ballbar pivot, R-test nests) whose positions are fitted, and every fit estimates the
/// location errors; so when some combination of one effect's parameters moves the table, at
/// every pose, exactly as a combination of the other's does together with location errors and
/// a shift of the table point, no test can separate them (e.g. gravity_sag_A and
/// radial_motion_A_h2: translations of the table that depend on A alone).
///
/// The table motion of a parameter is the derivative of the table pose (effects.hpp,
/// table_pose) as a spatial twist, rotation first: (omega x r_ref, v) with
/// omega = vee(dR R^T) (rad, times the reference radius to give mm) and v = dt - omega x t
/// (mm), at zero errors, on a grid over the tilt limits, a full turn of C and three times in
/// [0, duration]. The location errors and the table point (a translation in the table frame,
/// R dq) are projected out; the largest cosine of the principal angles between what is left of
/// the two effects is 1 when they share a motion.
struct TableMotionOverlap {
  bool moves_table_first = false;  ///< the first effect moves the table at all
  bool moves_table_second = false;
  bool first_is_location = false;  ///< all its motion is location errors + table point
  bool second_is_location = false;
  double cosine = 0.0;       ///< largest cosine of the principal angles, [0, 1]
  bool same_motion = false;  ///< cosine >= 1 - 1e-6, or an effect is all location
  /// Nesting: every table motion of the first, beyond the location errors and the table point,
  /// is one of the second's, and the second has more of them (the first is a special case with
  /// fewer parameters, as gravity_sag_A of radial_motion_A_h2). Never both.
  bool first_within_second = false;
  bool second_within_first = false;
  std::string why;  ///< in words, for reports
};

/// Compare the table motions of `a` and `b` on machine `m` over tilt in `tilt_limits_deg`, C
/// over a full turn and time over [0, duration_s]. Throws InvalidArgument naming the effect
/// that does not exist on the machine, or for a reversed tilt range or negative duration.
TableMotionOverlap table_motion_overlap(MachineType m, const Effect& a, const Effect& b,
                                        std::array<double, 2> tilt_limits_deg = {-90.0, 90.0},
                                        double duration_s = 3600.0,
                                        double reference_radius_mm = 100.0);

}  // namespace rotacal
