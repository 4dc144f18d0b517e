// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Flynn et al. (2016)'s identification chain, Sec. 3:
///  3.1 the pivot from the three arcs at rotary zero by a least-squares sphere (radius L0);
///  3.2 each radial test: the pivot estimated along the nominal bar direction at the measured
///      length (Eq. 2), projected on the plane of rotation, Hyper circle fit -> a point of
///      the axis' average line;
///  3.3 each axial test: the pivot's axial coordinate from the measured length, SVD plane fit
///      (Eq. 3) -> the axis direction (the plane's normal);
///  transport of each line to the nominal intersection of the axes -> the 8 location errors
///  (formats.md definitions). Uncertainties are propagated to first order from the fits'
///  covariances. The chain's small-error approximations are listed in the result's notes.

#include "rotacal/ballbar/identify.hpp"

namespace rotacal {

/// Throws InvalidArgument naming any of the seven tests the chain needs that the session
/// lacks, DegenerateGeometry if a fit is degenerate. `with_residuals` false leaves the
/// residuals (and residual_rms_um, sigma_um) out, for callers that use the identified values
/// only (ballbar/chain_runs.hpp): predicting every sample is about a quarter of the chain's time.
BallbarIdentification identify_paper(const BallbarSession& session, bool with_residuals = true);

}  // namespace rotacal
