// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Uncertainty budget of an R-test joint identification (rtest/identify_joint.hpp): the same
/// GUM / ISO/TR 230-9 budget as uncertainty_budget.hpp, but of the identification's own model,
/// the location errors with the smooth error maps (Oyama Eqs. 5-7), so that the budget's values
/// and type A are the identification's: one value per quantity. The diagnosis' baseline (location
/// errors without maps) would report other values and a smaller type A.
///  - type A: the identification's covariance (GLS under its noise model, bias-corrected);
///  - type B: per catalogue entry the R-test could see, the bias it puts on the location errors
///    through the map model's least squares; an effect the maps take up moves the map
///    coefficients, not the location errors, and its line is near zero.

#include "rotacal/diagnose/uncertainty_budget.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// Budget of the location errors of `identification`, the joint fit of `session` (dx, dy, dz
/// present: convert raw readings first, as the identification did). Throws InvalidArgument if
/// coverage is not in (0, 1), a size is negative, an override names no candidate of this
/// session, or the identification is not of this session.
UncertaintyBudget uncertainty_budget(const RtestSession& session,
                                     const RtestJointIdentification& identification,
                                     const PlausibleSizes& sizes = {}, double coverage = 0.95,
                                     int max_harmonic = 4);

}  // namespace rotacal
