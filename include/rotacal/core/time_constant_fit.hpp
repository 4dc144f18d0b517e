// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A joint fit whose model has time constants (the log of one, unit "1": thermal_warmup,
/// reversal_spike), shared by the instruments' fits (ballbar, touch probe, R-test).

#include <vector>

#include "rotacal/core/joint_fit.hpp"

namespace rotacal {

/// A time constant moves nothing while its amplitude is 0, where every fit starts, so the
/// observability analysis at the start would hold it there (300 s for thermal_warmup, and
/// the amplitude biased where the session's differs). Such a fit runs twice: with the time
/// constants held, then from that solution with them free. Without time constants, one
/// solve_joint.
JointFitOutcome solve_with_time_constants(const ResidualModel& model,
                                          std::vector<FitParameter> params,
                                          const JointFitSettings& settings);

}  // namespace rotacal
