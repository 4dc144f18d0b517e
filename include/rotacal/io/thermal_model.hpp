// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The thermal model file (kind "thermal", docs/model_file.md): what the joint fit of a thermal
/// session (session/thermal_result.hpp) identified, kept to predict the location errors for
/// another duty (`rotacal predict --duty`) and to export them at a lag state (`rotacal export
/// --at` / `--state`; thermal_export_input of io/controller_export.hpp). The errors at lag states
/// y_l are E0 + sum_l K_l y_l (kinematics/thermal_lag.hpp, the one lag implementation); their
/// covariance is propagated from the fit's covariance of the cold errors, each tau and the gains.

#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rotacal/io/model_file.hpp"
#include "rotacal/session/thermal_result.hpp"
#include "rotacal/session/thermal_test.hpp"

namespace rotacal {

/// One lag of a thermal model: its tau and its gains on the eight location errors.
struct ThermalModelLag {
  double tau_s = 0.0, tau_std_s = 0.0;
  Eigen::Matrix<double, 8, 1> gains = Eigen::Matrix<double, 8, 1>::Zero();  ///< mm, rad per u
  std::array<bool, 8> gain_observable{};
};

/// A thermal model as read from its file.
struct ThermalModel {
  MachineType machine = MachineType::AC_trt;
  char axis = 0;                  ///< the axis whose duty heats it
  double tested_speed_rpm = 0.0;  ///< the test's largest |speed|
  LocationErrors<double> cold;    ///< mm, rad (unobservable: 0)
  std::array<bool, 8> cold_observable{};
  std::vector<ThermalModelLag> lags;
  HeatInput test_heat;  ///< the test's heat input from its first row, its epochs' pauses included
  /// Covariance of (8 cold errors; per lag: tau_s, 8 error gains); 0 where not determined.
  Eigen::MatrixXd covariance;
  ModelFile file;  ///< the file as read (source, for the exports' header)
};

/// The location errors at one set of lag states, with their covariance.
struct ThermalErrorsAt {
  std::vector<double> y;  ///< per lag
  LocationErrors<double> errors;
  Eigen::Matrix<double, 8, 8> covariance = Eigen::Matrix<double, 8, 8>::Zero();
  std::array<bool, 8> observable{};  ///< false when the cold value or a gain is not determined
};

/// The document of a thermal model: location_errors (the cold ones), thermal (axis, tested
/// speed, the test's heat input, per lag tau and gains), covariance, fit. `test_heat` is the
/// session's (ThermalTest::heat_input of id.axis). InvalidArgument for an identification
/// without heat input (nothing to predict).
nlohmann::ordered_json thermal_model_document(const ThermalIdentification& id,
                                              const HeatInput& test_heat);

/// The checks of a "thermal" document's own members (model_from_json calls it); throws
/// InvalidArgument "source: member: what is wrong".
void check_thermal_model(const nlohmann::ordered_json& doc, MachineType machine,
                         const std::string& source);

/// The thermal model of a validated model file; InvalidArgument when it is not kind "thermal".
ThermalModel thermal_model(const ModelFile& file, const std::string& source);
/// Read a thermal model file (read_model refuses "thermal": its errors drift).
ThermalModel read_thermal_model(const std::string& path);

/// The errors at given lag states y (one per lag; exact, so tau adds no uncertainty).
/// InvalidArgument for the wrong number of states or one outside [0, 1000].
ThermalErrorsAt thermal_errors_at_state(const ThermalModel& m, const std::vector<double>& y);
/// The errors at time t (s, the clock of `heat`) of the heat input `heat`: y_l(t) by
/// lag_state, tau's uncertainty propagated with the gains'.
ThermalErrorsAt thermal_errors_at_time(const ThermalModel& m, const HeatInput& heat, double t);

/// Times of a prediction when the user gives none (s, the clock of `heat`): every `step_s` from
/// its first piece to 5 of the longest tau after its last (the drift within 1 % of its end).
std::vector<double> thermal_prediction_times(const ThermalModel& m, const HeatInput& heat,
                                             double step_s = 600.0);

}  // namespace rotacal
