#pragma once
/// \file
/// The joint fit with its noise model, for any instrument's problem: a white fit
/// (core/joint_fit.hpp), the AR noise model of its residuals per stream (core/noise_model.hpp),
/// and, when that model is correlated, a GLS refit under it with the covariance scaled for the
/// correlation the fit absorbs from its residuals (core/noise_handling.hpp). The ballbar and
/// R-test fits do the same steps inline today (issue 30, item 2: one fit_with_noise for all
/// instruments); the touch probe calls this one.

#include <string>
#include <vector>

#include "rotacal/core/joint_fit.hpp"
#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

struct NoiseFitOptions {
  /// `automatic`: estimate the noise model of the white fit's residuals and refit by GLS when
  /// it is correlated; `white`: residuals taken as independent.
  NoiseHandling noise = NoiseHandling::automatic;
  NoiseModelOptions noise_options;
  /// The GLS refit is done only when some stream's integrated correlation time reaches this
  /// (samples): below it the white covariance is within ~10 % (as the ballbar fit).
  double min_correlation_samples = 1.2;
  /// Scale the GLS covariance by the bootstrap bias factor (core/noise_handling.hpp).
  bool noise_bias_correction = true;
};

struct NoiseFitOutcome {
  JointFitOutcome fit;
  NoiseModel noise;          ///< of the white fit's residuals (empty with a given whitener)
  double correction = 1.0;   ///< variance factor applied to the GLS covariance
  bool refit = false;        ///< the fit was redone by GLS under `noise`
  std::string note;          ///< the words for a report when refit (empty otherwise)
};

/// solve_joint(model, parameters, settings); with no settings.whitener, the noise model of the
/// residuals grouped by `groups` in `times` order and, under options.noise = automatic and a
/// correlated model, the GLS refit. Throws InvalidArgument if groups or times do not hold one
/// value per residual, and whatever solve_joint throws.
NoiseFitOutcome fit_with_noise(const ResidualModel& model, const std::vector<FitParameter>& parameters,
                               JointFitSettings settings, const std::vector<std::string>& groups,
                               const std::vector<double>& times, const NoiseFitOptions& options = {});

}  // namespace rotacal
