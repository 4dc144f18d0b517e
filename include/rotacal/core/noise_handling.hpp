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
                               const std::vector<double>& times, const Eigen::MatrixXd& jacobian_free,
                               const NoiseModelOptions& options, int draws = 32,
                               std::uint64_t seed = 1);

/// One draw of the noise `model` describes (mm, one value per reading, its rows): per stream
/// the AR recursion with Gaussian innovations of s_e, started stationary (burn-in of many
/// correlation times). For Monte Carlo checks and the bias factor.
Eigen::VectorXd draw_noise(const NoiseModel& model, std::mt19937_64& rng);

/// Sum over streams of n_s s_e^2 / (1 - sum phi)^2 (mm^2 per reading x readings).
double long_run_variance(const NoiseModel& model);

}  // namespace rotacal

#include "rotacal/core/joint_fit.hpp"

namespace rotacal {

/// noise_model_bias_factor with the free columns of a (white) fit's Jacobian.
inline double noise_correction(const NoiseModel& model, const std::vector<std::string>& groups,
                               const std::vector<double>& times, const JointFitOutcome& white_fit,
                               const NoiseModelOptions& options) {
  std::vector<Eigen::Index> cols;
  for (std::size_t j = 0; j < white_fit.free.size(); ++j)
    if (white_fit.free[j]) cols.push_back(static_cast<Eigen::Index>(j));
  Eigen::MatrixXd J(white_fit.jacobian.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) J.col(static_cast<Eigen::Index>(k)) = white_fit.jacobian.col(cols[k]);
  return noise_model_bias_factor(model, groups, times, J, options);
}

/// Scale a fit's covariance and 1-sigma figures by `factor` (variance).
inline void apply_noise_correction(double factor, JointFitOutcome* fit) {
  fit->covariance *= factor;
  for (ParameterEstimate& e : fit->estimates)
    if (e.observable) e.std *= std::sqrt(factor);
}

}  // namespace rotacal
