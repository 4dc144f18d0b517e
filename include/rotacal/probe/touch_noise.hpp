// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The touch probe's noise model. A touch latches the machine's X, Y, Z; the noise of each
/// coordinate is AR(1) from one touch to the next (rho, marginal sigma per coordinate), and a
/// touch's residual sees it along its approach direction n_i:
///   Cov(e_i, e_j) = sigma^2 rho^|i - j| n_i . n_j   (touches in time order).
/// One AR stream of the residuals (what the other instruments' readings get) sees only
/// rho n_i . n_{i+1} from one touch to the next, which changes sign with the directions of a
/// pose, and so calls most such sessions white: their sigmas came out 10-18 % small
/// (bench/multi_bench, issue 57), and consistent sessions were reported to disagree in 3.5 %
/// of draws. The whitener is the Kalman filter of the three coordinates' AR states: O(n).

#include <Eigen/Core>
#include <memory>
#include <random>
#include <vector>

#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/core/whitener.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

/// W with W V W^T = I for V above, over the residuals `rows` (time order) of a fit of `size`
/// residuals; rows not listed are left as they are.
class TouchNoiseWhitener : public ResidualWhitener {
 public:
  /// Throws InvalidArgument for sigma <= 0, |rho| >= 1, a zero direction or sizes that differ.
  TouchNoiseWhitener(std::vector<Eigen::Index> rows, const std::vector<Eigen::Vector3d>& n,
                     double rho, double sigma_mm, Eigen::Index size);
  void apply(Eigen::Ref<Eigen::MatrixXd> columns) const override;
  Eigen::Index size() const override { return size_; }
  double log_det() const { return log_det_; }  ///< ln |V| of the listed rows (mm^2)

 private:
  std::vector<Eigen::Index> rows_;
  std::vector<Eigen::Vector3d> n_, gain_;
  std::vector<double> inv_sd_;
  double rho_ = 0.0, log_det_ = 0.0;
  Eigen::Index size_ = 0;
};

/// The touch noise of a probe session by REML over what its white fit leaves (`residuals_mm`,
/// one per touch in session order; `free_jacobian`: the fit's free columns): rho in [0, 0.95],
/// then sigma. `whitener` is null when rho comes out 0 (white: the white fit stands);
/// `described` says it as a one-stream AR(1) model of the coordinates (for reports and files).
struct TouchNoise {
  double rho = 0.0;
  double sigma_mm = 0.0;
  std::shared_ptr<const TouchNoiseWhitener> whitener;
  NoiseModel described;
};
TouchNoise estimate_touch_noise(const ProbeSession& session, const Eigen::VectorXd& residuals_mm,
                                const Eigen::MatrixXd& free_jacobian);

/// A draw of that noise for `session` (mm, one per touch in session order): each coordinate's
/// AR(1) at `rho` and marginal `sigma_mm` in time order, read along each touch's direction; what
/// a Monte Carlo check of a fit under this model must draw (probe/monte_carlo.cpp).
Eigen::VectorXd draw_touch_noise(const ProbeSession& session, double rho, double sigma_mm,
                                 std::mt19937_64& rng);

/// The NoiseFitOptions::own_noise of a probe session (kept alive by the returned function).
OwnNoiseModel touch_noise_model(std::shared_ptr<const ProbeSession> session);

}  // namespace rotacal
