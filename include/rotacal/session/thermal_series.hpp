// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The per-epoch peer of the thermal joint fit (issue 53): the method a user of a controller's
/// kinematics cycle (HEIDENHAIN cycle 452, re-run at intervals) has. Each epoch is identified
/// alone (its location errors and set-up, each with its 1 sigma), then one lag is fitted to
/// the series, one tau shared by every series:
///   v_k(e) = c_k + K_k y(t_e; tau),  weighted by 1 / sigma_k(e),
/// t_e the middle of epoch e, y the lag state of the duty (kinematics/thermal_lag.hpp). The
/// result has the joint fit's shape (session/thermal_result.hpp), so the same summary reads it.

#include <string>
#include <vector>

#include "rotacal/session/thermal_result.hpp"
#include "rotacal/session/thermal_test.hpp"

namespace rotacal {

/// Fit one lag (cold value and gain per series, one tau) to the series, epochs at times
/// `t_mid` (s) of `thermal`'s duty on `axis` (0: no heat input, every gain unobservable).
ThermalIdentification fit_lag_to_series(const std::vector<ThermalSeries>& series,
                                        const std::vector<double>& t_mid,
                                        const ThermalTest& thermal, char axis,
                                        const ThermalFitOptions& options = {});

}  // namespace rotacal
