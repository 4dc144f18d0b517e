// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Position-dependent geometric errors by the paper's two-step method (Oyama & Ibaraki, Sec. 4):
///  1. B-axis errors w(B_i) = (dx, dy, dz, alpha, beta, gamma)_BY by linear least squares over the
///     C sweep of every nest, relative to the reference pose B1 = C1 = 0 (Eqs. 10-15), with the
///     C-axis errors assumed zero;
///  2. C-axis errors per (B_i, C_j) from two or more nests (Eqs. 16-22): the residual left by the
///     B-axis errors, in the B-axis frame, is -(eps x P_k + delta) for nest k at P_k; the
///     difference between nests gives alpha_CB, beta_CB (gamma_CB = 0 assumed), then delta.
/// The session must hold every (B_i, C_j) of one grid for every nest, including B = C = 0.

#include <string>
#include <vector>

#include "rotacal/rtest/error_model.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

struct RtestPaperIdentification {
  std::string method = "paper";
  std::vector<double> b_deg;                          ///< B_i, deg (ascending)
  std::vector<double> c_deg;                          ///< C_j, deg (ascending)
  std::vector<AxisErrors<double>> w_BY;               ///< per B_i (mm, rad)
  std::vector<AxisErrors<double>> w_BY_std;           ///< 1 sigma per B_i (0 where assumed)
  std::vector<std::vector<AxisErrors<double>>> w_CB;  ///< [i][j], gamma_CB = 0 (assumed)
  std::vector<std::vector<AxisErrors<double>>> w_CB_std;
  double b_step_rms_um = 0.0;    ///< residual RMS of step 1 (includes what C errors cause)
  double residual_rms_um = 0.0;  ///< residual RMS after both steps (2 nests: 1 dof per pose)
  std::size_t n_samples = 0;
  std::vector<std::string> unobservable;  ///< what the method cannot see, in words
  std::vector<std::string> notes;         ///< the paper's assumptions

  /// w_BY at B (rad), linear interpolation between the B_i (clamped outside).
  AxisErrors<double> w_BY_at(double B) const;
  /// w_CB at (B, C) (rad), bilinear, periodic in C.
  AxisErrors<double> w_CB_at(double B, double C) const;
  /// Predicted reading at (B, C) for the nest at q (table frame, mm), relative to the reference
  /// pose B = C = 0 (the paper's datum): exact Eq. 4 with the interpolated maps.
  Eigen::Vector3d predict_reading(const Eigen::Vector3d& q, double B, double C) const;
};

/// The paper's method. Throws InvalidArgument if the session is not BC-trt, a sample lacks d,
/// the grid is incomplete or has no B = C = 0 pose, or fewer than 2 nests are present.
RtestPaperIdentification identify_paper(const RtestSession& session);

}  // namespace rotacal
