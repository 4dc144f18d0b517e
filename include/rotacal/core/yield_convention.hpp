// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The convention by which a fit reports parameters that trade off against each other only in
/// part. A catalogue effect can share some of its directions with the baseline: a first-order
/// wobble of C that turns with the table (tilt_motion_C_h1, effects.md) is, in its forward-
/// turning half, exactly a tilt of C's axis line (E_A0C, E_B0C) with a constant probe offset.
/// Holding one parameter per shared direction (Observability::to_fix) would leave every
/// parameter that takes part undetermined, the wobble's distinct half included. Instead the
/// effect *yields*: along each shared direction the solution moves until the yielding
/// parameters have no component along it (scaled by their plausible magnitudes), so the
/// baseline keeps the shared part (the axis tilt stays a location error) and the effect holds
/// only what the baseline cannot express. Both are then determined.

#include <Eigen/Core>
#include <vector>

#include "rotacal/core/least_squares.hpp"

namespace rotacal {

/// The linear map M (m x m, m = number of analysed parameters) that takes a solution with
/// Observability::to_fix held to the yield convention: x' = M x. `yields[j]`: parameter j
/// yields; `scales`: plausible magnitudes (as for the observability). A null direction is
/// resolved by the convention when it is a trade-off: both its yielding part and its other part
/// (in scaled units, over an orthonormal basis of the null space split by the SVD of the
/// yielding part) are at least 0.3 of it. A null
/// direction within the yielding parameters alone (a component of an effect the instrument
/// cannot see) is not a trade-off and stays unobservable. `observable` (in:
/// Observability::observable) is updated: a parameter is observable when it takes no part (share <=
/// 0.05) in the null directions left unresolved. Returns an empty matrix when no null direction
/// moves a yielding parameter.
Eigen::MatrixXd yield_convention(const Observability& o, const std::vector<bool>& yields,
                                 const Eigen::VectorXd& scales, std::vector<bool>* observable);

}  // namespace rotacal
