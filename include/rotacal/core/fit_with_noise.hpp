// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one feasible-GLS sequence of every instrument's joint fit (the ballbar's and the
/// R-test's): white fit -> noise model of its residuals (one AR stream per group, time order)
/// -> when the noise is correlated, the same fit again by GLS under that model's whitener,
/// from the same start values (the noise model is not re-estimated: one GLS step).
///
/// With correlated noise the white covariance is too small by about sqrt(tau) (issue 11: 6x
/// at rho 0.95). The noise model of the residuals is biased towards white, because the fit
/// takes the slow part of the noise; two remedies, as the instrument asks:
/// - the bootstrap bias factor (noise_model_bias_factor) scales the GLS covariance;
/// - REML of AR(1) + a random walk over the fit's residual space (estimate_noise_model_reml),
///   which has no bias left to scale (the R-test, whose probe zeros wander between poses).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/joint_fit.hpp"
#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

/// An instrument's own noise model of its white fit's residuals (the touch probe's,
/// probe/touch_noise.hpp): the GLS whitener (null: white, the white fit stands), and in
/// `described` the model as reports and files say it.
using OwnNoiseModel = std::function<std::shared_ptr<const ResidualWhitener>(
    const JointFitOutcome& white_fit, NoiseModel& described)>;

/// The noise handling options every instrument's fit options carry (ballbar JointFitOptions,
/// RtestJointOptions, ProbeFitOptions, MultiFitOptions), as their member `noise`.
struct NoiseFitOptions {
  /// `automatic`: noise model of the white fit's residuals, GLS refit when it is correlated;
  /// `white`: one fit, no noise model.
  NoiseHandling noise = NoiseHandling::white;
  NoiseModelOptions noise_options;
  /// The GLS refit is done only when some stream's integrated correlation time reaches this
  /// (samples): below it the white covariance is within ~10 % and BIC's rare spurious AR(1) of
  /// white noise (|phi| ~ 0.05) must not change the answer.
  double min_correlation_samples = 1.2;
  /// Scale the GLS covariance by the bootstrap bias factor (core/noise_handling.hpp).
  bool noise_bias_correction = true;
  /// REML of AR(1) + a random walk when noise_options.reml_random_walk is set and no stream
  /// is longer than noise_options.reml_max_stream_size (the R-test); else Burg + bias factor.
  bool allow_reml = false;
  /// Under `automatic`, used instead of the AR streams when set; no bias factor (REML).
  OwnNoiseModel own_noise;
};

struct NoiseFit {
  JointFitOutcome fit;  ///< the white fit, or the GLS refit when `refit`
  NoiseModel noise;     ///< noise model of the white fit's residuals (empty: not estimated)
  bool refit = false;   ///< the fit was redone by GLS under `noise`
  bool reml = false;    ///< `noise` is REML's AR(1) + random walk
  double scale = 1.0;   ///< bias factor applied to the GLS covariance
  std::shared_ptr<const ResidualWhitener> whitener;  ///< of the GLS refit (when `refit`)
};

/// `solve(settings)` runs the instrument's fit. With settings.whitener set (the caller's own
/// noise model) or `groups` empty (no streams known), the fit is run once and no noise model
/// estimated. Otherwise `groups` and `times` name the stream and the time (s) of every
/// residual, in residual order.
NoiseFit fit_with_noise(const std::function<JointFitOutcome(const JointFitSettings&)>& solve,
                        JointFitSettings settings, const std::vector<std::string>& groups,
                        const std::vector<double>& times, const NoiseFitOptions& options);

}  // namespace rotacal
