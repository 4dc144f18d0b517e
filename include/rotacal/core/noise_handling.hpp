// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// How a joint fit (ballbar or R-test) treats correlated residual noise.

#include <string>

#include "rotacal/core/noise_model.hpp"

namespace rotacal {

enum class NoiseHandling {
  automatic,  ///< fit, estimate the AR noise model per stream, refit by GLS if it is not white
  white       ///< residuals taken as independent (the covariance is (J^T J)^-1 s^2)
};

/// "auto" or "white" (the names of the CLI and Python); throws InvalidArgument naming `noise`.
NoiseHandling noise_handling_from_string(const std::string& noise);

}  // namespace rotacal

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace rotacal {

/// How much the GLS covariance under a noise model estimated from fit residuals must be
/// scaled up. The residuals are the noise with the fitted directions projected out
/// (r = (I - J (J^T J)^-1 J^T) e): the fit absorbs the slow part of correlated noise, so Burg
/// on r under-estimates the correlation and the long-run variance s_e^2 / (1 - sum phi)^2 that
/// the parameters' sigma rests on (at rho 0.95 the ballbar sigmas come out ~1.3x too small).
/// Bootstrap bias correction (as Kilian's for AR estimates): draw `draws` noise series from
/// `model` (seeded, stationary start), project them as the fit does with `jacobian_free`
/// (residual rows x free parameters, in the residuals' units per parameter), re-estimate the
/// noise model with `options`, and return the long-run variance of `model` over the mean of
/// the re-estimated ones (summed over streams by size), at least 1. Throws InvalidArgument
/// if the sizes differ.
double noise_model_bias_factor(const NoiseModel& model, const std::vector<std::string>& groups,
                               const std::vector<double>& times,
                               const Eigen::MatrixXd& jacobian_free,
                               const NoiseModelOptions& options, int draws = 32,
                               std::uint64_t seed = 1);

/// Restricted maximum likelihood (REML, Patterson & Thompson 1971) of an AR(1) + random-walk
/// noise model on the streams of `start` (a Burg model of the same residuals: its streams,
/// rows, sample intervals and phi_1 as the start point). Per stream s (time order, positions
/// i, j):
///   V_s = sigma^2 a_s [ rho^|i-j| + lambda min(i, j) ],
/// rho and lambda (the walk's step variance over the AR marginal one) shared by all streams,
/// a_s a stream's relative level (geometric mean 1) and sigma^2 profiled out. REML maximises
/// the likelihood of the residuals' contrasts, i.e. of what the fit leaves, with
///   -2 l = (n - k) ln(S / (n - k)) + ln|V| + ln|X^T V^-1 X|,  S = min_b |V^-1/2 (y - X b)|^2,
/// X = `jacobian_free` (rows x free parameters, k its rank): it accounts for the slow noise
/// that the fitted directions take from the residuals (a probe zero, polynomials of B in an
/// R-test whose poses run B outer), which a model of the residuals alone misses (Burg on
/// them sees a walk as a mild AR). (rho, ln lambda) by Nelder-Mead; a_s by the fixed-point
/// step a_s <- a_s (|e_s|^2 / n_s) / (S / n) on the whitened GLS residuals e, then once more.
/// Each evaluation whitens an orthonormal basis of the Jacobian's span (made once) by
/// ArWalkFilter (O(n) per column) and takes the Cholesky factor of its Gram matrix beside the
/// residuals (O(n k^2) as a matrix product), or a column-pivoted QR where that is near singular.
/// Throws InvalidArgument if the sizes differ.
NoiseModel estimate_noise_model_reml(const NoiseModel& start, const Eigen::VectorXd& residuals_mm,
                                     const Eigen::MatrixXd& jacobian_free);

/// One draw of the noise `model` describes (mm, one value per reading, its rows): per stream
/// the AR recursion with Gaussian innovations of s_e, started stationary (burn-in of many
/// correlation times). For Monte Carlo checks and the bias factor.
Eigen::VectorXd draw_noise(const NoiseModel& model, std::mt19937_64& rng);

/// Sum over streams of n_s s_e^2 / (1 - sum phi)^2 (mm^2 per reading x readings).
double long_run_variance(const NoiseModel& model);

}  // namespace rotacal

#include "rotacal/core/joint_fit.hpp"

namespace rotacal {

/// The free columns of a fit's Jacobian (measurement units per parameter).
inline Eigen::MatrixXd free_jacobian(const JointFitOutcome& fit) {
  std::vector<Eigen::Index> cols;
  for (std::size_t j = 0; j < fit.free.size(); ++j)
    if (fit.free[j]) cols.push_back(static_cast<Eigen::Index>(j));
  Eigen::MatrixXd J(fit.jacobian.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k)
    J.col(static_cast<Eigen::Index>(k)) = fit.jacobian.col(cols[k]);
  return J;
}

/// noise_model_bias_factor with the free columns of a (white) fit's Jacobian.
inline double noise_correction(const NoiseModel& model, const std::vector<std::string>& groups,
                               const std::vector<double>& times, const JointFitOutcome& white_fit,
                               const NoiseModelOptions& options) {
  return noise_model_bias_factor(model, groups, times, free_jacobian(white_fit), options);
}

/// Scale a fit's covariance and 1-sigma figures by `factor` (variance).
inline void apply_noise_correction(double factor, JointFitOutcome* fit) {
  fit->covariance *= factor;
  for (ParameterEstimate& e : fit->estimates)
    if (e.observable) e.std *= std::sqrt(factor);
}

}  // namespace rotacal
