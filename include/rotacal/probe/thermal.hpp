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

#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/io/thermal_file.hpp"
#include "rotacal/probe/touch_model.hpp"

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
  std::string noise;  ///< the noise model's summary (empty: white)
  std::vector<std::string> notes;
};

/// Identify a thermal probe session. Throws InvalidArgument for a session whose duty turns no
/// axis or more than one (one thermal_location_R at a time for now), or with too few touches.
ThermalIdentification identify_thermal_probe(const ProbeSession& session,
                                             const ThermalTest& thermal,
                                             const ThermalFitOptions& options = {});

/// Touch residuals (mm) of a thermal model given as the fit's parameter vector (tests, peer).
Eigen::VectorXd thermal_probe_residuals(const ProbeSession& session, const ThermalTest& thermal,
                                        int lags, const Eigen::VectorXd& x);

}  // namespace rotacal
