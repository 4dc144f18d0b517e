// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What the joint fit of a thermal session (probe/thermal.hpp) gives: the cold location errors
/// and set-up, and per lag of `thermal_location_R` (effects.md) its time constant and its gains
/// on every location error and on the instrument's table-side point, each with its 1 sigma or
/// the reason the session cannot determine it. session/thermal_summary.hpp reads it for the
/// user's questions (how far, how fast, when to re-measure).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

struct ThermalFitOptions {
  int lags = 1;  ///< 1, or 2 (a fast lag of the bearing, a slow one of the structure)
  double tau_start_s = 1800.0;  ///< start of tau_1; tau_2 starts at 4x
  int max_iterations = 100;
  double observability_min_chi2 = 1.0;
  NoiseFitOptions noise;  ///< white by default
};

/// One identified gain (or cold value) with its reason when the session cannot determine it.
struct ThermalGainEstimate {
  std::string name;  ///< location error name, or "q_x", "q_y", "q_z" (the table-side point)
  std::string unit;  ///< "mm" or "rad"
  double value = 0.0, std = 0.0;
  bool observable = true;
  std::string reason;  ///< why it is unobservable (empty when observable)
};

struct ThermalLag {
  double tau_s = 0.0, tau_std_s = 0.0;
  bool tau_observable = true;
  std::vector<ThermalGainEstimate> gains;  ///< 8 location errors, then q_x, q_y, q_z
};

/// One quantity identified epoch by epoch (a location error, or the table-side point's x).
struct ThermalSeries {
  std::string name;                ///< the gain's name: a location error's, or "q_x", "q_y", "q_z"
  std::string unit;                ///< "mm" or "rad"
  std::vector<double> value, std;  ///< per epoch; std <= 0: that epoch did not determine it
};

/// The result of the joint thermal fit.
struct ThermalIdentification {
  MachineType machine = MachineType::AC_trt;
  char axis = 0;                          ///< the axis the duty turns
  double tested_speed_rpm = 0.0;          ///< its largest |speed| in the duty
  std::vector<ThermalGainEstimate> cold;  ///< cold location errors, then the sphere's x, y, z
  std::vector<ThermalLag> lags;
  std::vector<ParameterEstimate> parameters;  ///< every fit parameter, in layout order
  Eigen::MatrixXd covariance;                 ///< of `parameters`
  /// Index in `parameters` of lag l's ln-tau and of its first gain (11 consecutive).
  std::vector<int> tau_index, gain_index;
  std::vector<std::string> unobservable;  ///< the driver's null directions in words
  bool converged = false;
  double residual_rms_um = 0.0;
  std::size_t n_samples = 0, n_epochs = 0;
  /// Degrees of freedom of the residuals behind the covariance: samples (the noise model's
  /// effective samples where it is coloured) less the free parameters; 0: not known (the
  /// summary's drift test then takes the covariance as exact).
  double residual_dof = 0.0;
  std::string noise;  ///< the noise model's summary (empty: white)
  std::vector<std::string> notes;
  /// The per-epoch peer's series, what its lag was fitted to (session/thermal_series.hpp), at
  /// the epochs' middle times (s); empty for the joint fit.
  std::vector<ThermalSeries> epoch_series;
  std::vector<double> epoch_mid_s;
};

/// Where a thermal fit keeps what: parameter indices of the cold values, of each lag's ln tau
/// and first gain, the gains' names and the cold value each gain moves (-1: none), so that
/// every instrument's thermal fit runs and reports through the same two functions below.
struct ThermalFitIndex {
  std::vector<int> cold;                ///< parameter index of each cold value
  std::vector<std::string> cold_names;  ///< their names
  std::vector<int> tau;                 ///< per lag: index of ln(tau / 300 s)
  std::vector<int> gains;               ///< per lag: index of its first gain
  std::vector<std::string> gain_names;  ///< per gain of a lag
  std::vector<int> gain_cold;           ///< per gain: its cold value in `cold`, -1 none
};

/// The joint fit: tau held, then free (core/time_constant_fit.hpp), with the noise model of
/// core/fit_with_noise.hpp; without heat input (`heated` false) tau and the gains are held at
/// their start (0: nothing moves them).
NoiseFit fit_thermal(const ResidualModel& model, std::vector<FitParameter> params,
                     const ThermalFitIndex& index, bool heated, const JointFitSettings& settings,
                     const std::vector<std::string>& groups, const std::vector<double>& times,
                     const ThermalFitOptions& options);

/// The result of fit_thermal in the instrument's words (axis, speed and counts left to it).
ThermalIdentification thermal_identification(const NoiseFit& nf, const ThermalFitIndex& index,
                                             bool heated);

}  // namespace rotacal
