// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What an identification reports, whatever the instrument (issue 51, step 1): the estimates
/// and their covariance, the fit's figures and the noise model of its residuals. The
/// instrument-specific parts (the ballbar's pivot, the R-test's probe zeros, the probe's
/// sphere, the effects) are named blocks of `parameters` (core/parameter_layout.hpp), read with
/// `block`, not members of their own. Each instrument's result (ballbar/identify.hpp,
/// rtest/identify_joint.hpp, probe/identify.hpp) adds only its machine model.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/core/parameter_layout.hpp"

namespace rotacal {

struct Identification {
  std::string method;  ///< "joint", or the instrument's peer method ("paper", "cycles")
  /// One estimate per parameter, in the fit's vector order (the blocks' order).
  std::vector<ParameterEstimate> parameters;
  /// The named blocks of `parameters` ("location_errors", "pivot", "zeros", "sphere",
  /// "tool_offset", "effects", ... as the instrument's problem lays them out).
  ParameterLayout blocks;
  Eigen::MatrixXd covariance;  ///< in `parameters` order, 1-sigma^2 (empty: no uncertainty)
  /// measured - model per residual at the solution, mm, in the instrument's residual order
  /// (ballbar: one per sample of the session, 0 for samples not fitted; R-test: dx dy dz per
  /// sample; probe: one per touch).
  std::vector<double> residuals;
  /// d residual / d parameter at the solution (rows: the fitted residuals, columns:
  /// `parameters`); empty when the instrument does not keep it.
  Eigen::MatrixXd jacobian;
  std::vector<bool> fixed;  ///< per parameter: held at its start value (empty: none kept)
  double residual_rms_um = 0.0;
  double sigma_um = 0.0;  ///< noise level the covariance rests on
  std::size_t n_samples = 0;
  bool converged = false;
  int iterations = 0;
  std::vector<std::string> unobservable;  ///< combinations the data cannot see, in words
  std::vector<std::string> notes;         ///< assumptions and warnings for the report
  FitSummary summary;                     ///< solver figures; whitened chi2/dof with a whitener
  /// Noise model of the residuals, estimated after the white fit; when it is correlated (and
  /// the noise handling is automatic) the covariance is the GLS one under it.
  NoiseModel noise;
  /// Factor applied to the GLS covariance for the noise model's bias (estimated from
  /// residuals that the fit has already taken the slow noise from): core/noise_handling.hpp.
  double noise_correction = 1.0;
  bool noise_refit = false;  ///< the fit was redone by GLS under `noise`

  /// The estimate called `name`; throws InvalidArgument if there is none.
  const ParameterEstimate& parameter(const std::string& name) const;
  /// The estimates of block `name`, in vector order; throws InvalidArgument naming the block
  /// when the identification has none of that name.
  std::vector<ParameterEstimate> block(const std::string& name) const;
};

/// The common part of a joint fit's identification from the outcome of fit_with_noise:
/// estimates, covariance, Jacobian, held parameters, unobservable combinations, solver figures
/// and noise model. residual_rms_um is over every residual of the fit; sigma_um is the fit's
/// residual sigma, dof-corrected when `dof_corrected` or when the covariance rests on a
/// whitener (`whitened`, or the GLS refit). `residuals` are the fit's, in its residual order
/// (the caller may place them otherwise); n_samples and notes are the caller's.
Identification joint_identification(NoiseFit nf, ParameterLayout blocks, bool whitened,
                                    bool dof_corrected = false);

/// The note that says the covariance is the GLS one under the fitted noise model (empty when
/// the fit was not redone under it).
std::string noise_refit_note(const NoiseFit& nf);

}  // namespace rotacal
