// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The `rotacal-model/1` kinds of a touch-probe identification ("probe") and of one
/// identification from several sessions ("multi") (docs/model_file.md), in plain values: the
/// location errors with their uncertainties and covariance, the effects fitted along (then the
/// values are the extended model's), the sessions that went in (instrument, file, their own
/// parameters, noise model) and the fit's summary. probe/model_document.hpp and
/// multi/model_document.hpp fill it from an identification; the reader (model_file.hpp)
/// validates these kinds through fitted_model_content, so every file is read back strictly.
///
///     write_model(fitted_model_document(content), "model.json");
///     const FittedModelContent c = fitted_model_content(read_model("model.json"), "model.json");

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/io/model_file.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

/// One session that went into the identification.
struct FittedSessionContent {
  std::string name;        ///< the session as named (its file)
  std::string instrument;  ///< "ballbar", "rtest" or "probe"
  /// Its own parameters in the fit (probe: sphere.x/y/z, tool_offset_Z on a machine with head
  /// axes; ballbar: pivot_x/y/z; R-test: zero.<set-up>.x/y/z, ...).
  std::vector<ParameterEstimate> nuisances;
  /// "multi": its location errors, then the shared effects' parameters, fitted alone (empty for
  /// "probe").
  std::vector<ParameterEstimate> alone;
  NoiseModel noise;               ///< of its residuals (streams keep no rows)
  bool noise_refit = false;       ///< the fit whitened it by `noise` (GLS)
  double noise_correction = 1.0;  ///< bias factor on its covariance
  double residual_rms_um = 0.0;
  std::size_t n_residuals = 0;
};

/// Two sessions fitted alone disagree on a parameter ("multi").
struct FittedDisagreement {
  std::string parameter, unit, session_a, session_b;
  double value_a = 0.0, value_b = 0.0, difference = 0.0, sigma = 0.0, z = 0.0;
};

struct FittedModelContent {
  std::string kind = "probe";  ///< "probe" or "multi"
  MachineType machine = MachineType::AC_trt;
  /// The 8 location errors, location_error_names(machine) order; an unobservable one is written
  /// with value and std null and read back with value 0, std NaN.
  std::vector<ParameterEstimate> location_errors;
  /// The catalogue effects fitted along (the values are then the extended model's: "model":
  /// "extended"; none: "baseline"), their parameters named effect_parameter_name, EffectModel
  /// order.
  EffectModel effects;
  std::vector<ParameterEstimate> effect_parameters;
  /// Names of the covariance's rows: location errors, effect parameters and the sessions'
  /// parameters ("probe": as named; "multi": "<session>:<name>"), in the fit's order.
  std::vector<std::string> covariance_parameters;
  Eigen::MatrixXd covariance;  ///< 1 sigma^2; NaN entries (written null): not determined
  std::vector<FittedSessionContent> sessions;  ///< "probe": exactly one
  std::vector<FittedDisagreement> disagreements;
  bool converged = false;
  double chi2_per_dof = 0.0;
  std::vector<std::string> unobservable;  ///< combinations the data cannot see, in words
  std::vector<std::string> notes;
  /// "multi": the sigmas of disagreeing parameters were widened at the user's request
  /// (written "fit.sigma_inflated"; a file without it: false). Export refuses a multi model
  /// whose sessions disagree unless it is true.
  bool sigma_inflated = false;
};

/// The document of a "probe" or "multi" model. InvalidArgument when the content is not one
/// (a kind, a count of location errors or effect parameters, a covariance of the wrong size).
nlohmann::ordered_json fitted_model_document(const FittedModelContent& content);

/// The content of a validated "probe" or "multi" model file; `source` names the file in
/// messages. InvalidArgument "source: member: what is wrong" for a model of another kind.
FittedModelContent fitted_model_content(const ModelFile& model, const std::string& source);

/// The check model_from_json runs on a "probe" or "multi" document (after the members every
/// kind shares): InvalidArgument "source: member: what is wrong".
FittedModelContent fitted_model_from_json(const nlohmann::ordered_json& document,
                                          MachineType machine, const std::string& source);

}  // namespace rotacal
