// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Identification of a thermal touch-probe session (issue 53; formats.md "Thermal test of a
/// rotary axis", effects.md `thermal_location_R`): one joint fit over every touch of every
/// epoch through the one driver (core/joint_fit.hpp, core/fit_with_noise.hpp):
///   r_i = touch_residual(E0 + sum_l K_l y_l(t_i), q0 + sum_l Kq_l y_l(t_i))
/// with the cold location errors E0 and sphere q0 (the set-up), each lag's gains K_l (every
/// location error) and Kq_l (the sphere, table frame) and its time constant tau_l = 300 s e^q_l
/// (fitted as q_l: tau is positive and its error is relative), y_l the lag state of the duty
/// (kinematics/thermal_lag.hpp). Gains the session cannot determine are held at 0 and reported
/// unobservable with the reason.

#include <optional>
#include <string>
#include <vector>

#include "rotacal/io/thermal_file.hpp"
#include "rotacal/probe/touch_model.hpp"
#include "rotacal/session/thermal_result.hpp"

namespace rotacal {

/// Identify a thermal probe session. Throws InvalidArgument for a session whose duty turns no
/// axis or more than one (one thermal_location_R at a time for now), or with too few touches.
ThermalIdentification identify_thermal_probe(const ProbeSession& session,
                                             const ThermalTest& thermal,
                                             const ThermalFitOptions& options = {});

/// The per-epoch peer (session/thermal_series.hpp): each epoch's touches identified alone
/// (identify_probe, white noise), then one lag fitted to the 11 series (location errors and
/// the sphere's x, y, z as the table-side point). Same exceptions as identify_thermal_probe.
ThermalIdentification thermal_peer_probe(const ProbeSession& session, const ThermalTest& thermal,
                                         const ThermalFitOptions& options = {});

/// Touch residuals (mm) of a thermal model given as the fit's parameter vector (tests, peer).
Eigen::VectorXd thermal_probe_residuals(const ProbeSession& session, const ThermalTest& thermal,
                                        int lags, const Eigen::VectorXd& x);

}  // namespace rotacal
