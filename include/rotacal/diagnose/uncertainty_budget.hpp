// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Uncertainty budget of every identified location error, in the manner of the GUM (JCGM
/// 100:2008) and ISO/TR 230-9:
///  - type A from the noise model: the covariance of the final fit with the residuals
///    whitened by the diagnosis' noise model (GLS), degrees of freedom from the noise model's
///    effective number of samples;
///  - type B, one line per catalogue effect the final model leaves out: the bias it would put
///    on each location error, (J^T J)^-1 J^T J_effect * size (the fits are unweighted least
///    squares), with `size` the half-width of a rectangular distribution (u = a / sqrt 3): the
///    session's bound where the session can see the effect (its linearised estimate on the
///    final residuals, |value| + 2 sigma, if that is below the default), else a documented
///    default plausible size (PlausibleSizes, docs/effects.md);
///  - combined standard uncertainty, Welch-Satterthwaite effective degrees of freedom (type B
///    lines from default sizes count as exactly known bounds, nu = infinity), Student-t
///    coverage factor and expanded uncertainty; the left-out effects that dominate.

#include <map>
#include <string>
#include <vector>

#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal {

/// Default plausible sizes of the catalogue effects, as half-widths of rectangular
/// distributions. Override any effect by id ("linear_squareness_XY") or one parameter by
/// "id.name" ("straightness_YX.c2") in `overrides` (the same units as the parameter).
struct PlausibleSizes {
  double squareness_rad = 20e-6;          ///< linear_squareness_*
  double straightness_mm = 5e-3;          ///< straightness_DA: deviation over ...
  double straightness_length_mm = 300.0;  ///< ... this length (centred)
  double drift_mm = 2e-3;                 ///< thermal_drift_*, ballbar_thermal_drift: over the test
  double warmup_mm = 2e-3;                ///< thermal_warmup_*: d
  double tool_length_mm = 10e-3;          ///< tool_offset_Z
  double tool_offset_mm = 10e-3;          ///< tool_offset_X/Y
  double bar_length_mm = 1e-3;            ///< ballbar_length_offset (length calibration)
  double scale = 10e-6;                   ///< linear_scale_* (10 um/m)
  double angular_error_rad = 20e-6;       ///< angular_error_* (pitch over 100 mm of travel)
  double rotary_zero_rad = 20e-6;         ///< rotary_zero_offset_*
  double angular_positioning_rad = 10e-6;  ///< angular_positioning_*_hn
  double error_motion_mm = 1e-3;           ///< radial/axial_motion_*_hn
  double tilt_motion_rad = 10e-6;          ///< tilt_motion_*_hn
  double gravity_sag_mm = 2e-3;            ///< gravity_sag_*
  double coning = 20e-6;                   ///< coning_* (rad/rad)
  double backlash_rad = 20e-6;             ///< backlash_* (lost motion of a rotary drive)
  double servo_lag_s = 1e-3;               ///< servo_lag_* (gain mismatch of a few percent)
  double reversal_spike_rad = 20e-6;       ///< reversal_spike_*: h
  double stylus_radius_mm = 0.5e-3;        ///< stylus_radius_offset (stylus calibration)
  double probe_lobing_mm = 0.5e-3;         ///< probe_lobing: lc, ls (after the probe's calibration)
  std::map<std::string, double> overrides;
  /// Use the session's bound where it is tighter than the default (false: defaults only).
  bool use_session_bounds = true;
};

/// One left-out effect's contribution to one location error.
struct BudgetLine {
  std::string effect;
  std::string basis;               ///< "session bound" or "default plausible size"
  double u = 0.0;                  ///< standard uncertainty it contributes (location error's unit)
  double bias_at_size = 0.0;       ///< largest |bias| at the half-width (a), before / sqrt 3
  double dof = 0.0;                ///< infinity for default sizes
  std::vector<double> half_width;  ///< a of each of the effect's parameters (its units)
};

struct LocationBudget {
  std::string name;
  std::string unit;
  bool observable = true;  ///< false: no budget (the session cannot determine it)
  double value = 0.0;
  double u_a = 0.0;                ///< type A, from the noise model
  double dof_a = 0.0;              ///< effective samples - free parameters
  std::vector<BudgetLine> type_b;  ///< largest first
  double u_c = 0.0;                ///< combined standard uncertainty
  double nu_eff = 0.0;             ///< Welch-Satterthwaite (infinity when type B dominates)
  double k = 0.0;                  ///< coverage factor for `coverage`
  double expanded = 0.0;           ///< U = k u_c
  /// Left-out effects with the largest share of u_c^2 (at least 10 %), largest first.
  std::vector<std::string> dominant;
};

struct UncertaintyBudget {
  double coverage = 0.95;
  std::vector<LocationBudget> errors;  ///< the 8 location errors, in order
};

/// Rows on which a long session's left-out effects are evaluated for the budget's type B
/// (DiagnosisProblem::visit_candidate_jacobians_reduced); type A uses every row. At 90,000
/// ballbar samples the expanded uncertainties move by less than 1 % (bench/long_session_budget.py).
constexpr std::size_t kBudgetDesignRows = 8192;

/// Budget of the location errors of `diagnosis.final_fit`. `problem` must be the one the
/// diagnosis ran on. `design_rows`: kBudgetDesignRows, 0 for every row. Throws
/// InvalidArgument if coverage is not in (0, 1), a size is negative, or an override names no
/// candidate of this problem.
UncertaintyBudget uncertainty_budget(const DiagnosisProblem& problem, const Diagnosis& diagnosis,
                                     const PlausibleSizes& sizes = {}, double coverage = 0.95,
                                     int max_harmonic = 4,
                                     std::size_t design_rows = kBudgetDesignRows);

/// Default half-width of each parameter of `effect` for a session lasting `duration_s`.
std::vector<double> plausible_sizes(const Effect& effect, const PlausibleSizes& sizes,
                                    double duration_s);

}  // namespace rotacal
