// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Design of the R-test measurement before the machine runs it: the two nest positions
/// (radius from the C axis, height above the B axis) and the pose grid (B and C steps within
/// the rotary limits) whose joint fit (rtest/identify_joint.hpp: location errors, the smooth
/// maps of both axes and a probe zero per nest) gives the smallest largest expanded uncertainty
/// (k = 2) of the eight location errors at a time budget, within the machine's travel.
///
/// Information: the R-test joint fit is called on the noise-free readings of the nominal
/// machine with the whitener of the noise (AR(1) with coefficient rho between successive
/// readings of one nest and component, marginal sigma; white for rho = 0), so its covariance
/// is exactly (J^T Sigma^-1 J)^-1, the inverse Fisher information of that fit: what a GLS fit
/// (identify --noise auto on correlated data) realises. Unlike the ballbar design's effective
/// samples, this holds when successive poses are far apart (a coarse C step), where AR noise
/// costs less than (1 + rho) / (1 - rho). Run time: every pose of every nest takes `dwell_s`
/// (hw/pose_window.hpp), so a pattern lasts poses x nests x dwell; a pattern shorter than the
/// budget is repeated to fill it, which scales the information by budget / run time. Nests: the
/// first on +X at (r1, 0, h1), the second on -Y at (0, -r2, h2), as in Oyama and Ibaraki's set-up;
/// nests and grid are chosen one after the other (nests at the base grid, then the grid at the
/// chosen nests), which keeps the design within a few seconds.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "rotacal/core/joint_fit.hpp"
#include "rotacal/design/separation.hpp"
#include "rotacal/design/table_motion.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/simulate.hpp"

namespace rotacal {

struct RtestDesignOptions {
  RtestPattern base;  ///< the default pattern (nests, grid, dwell) the design is compared with
  std::vector<double> nest_radius_mm = {50.0, 100.0, 150.0};        ///< from the C axis
  std::vector<double> nest_height_mm = {20.0, 60.0, 100.0, 140.0};  ///< above the B axis
  std::vector<double> b_step_deg = {15.0, 30.0, 45.0};              ///< B grid steps tried
  std::vector<double> c_step_deg = {30.0, 45.0, 60.0};  ///< C grid steps tried (full turn)
  std::array<double, 2> b_limits_deg = {-90.0, 90.0};   ///< rotary limits of B
  /// Travel of X, Y, Z (machine frame of formats.md: origin at the nominal intersection of B
  /// and C), mm; every commanded sphere centre must lie within it.
  Eigen::Vector3d travel_min = Eigen::Vector3d(-400, -300, -300);
  Eigen::Vector3d travel_max = Eigen::Vector3d(400, 300, 400);
  double time_budget_s = 0.0;          ///< 0: the base pattern's run time
  double noise_um = 0.3;               ///< 1 sigma per reading component (dx, dy, dz)
  double noise_rho = 0.0;              ///< AR(1) coefficient between readings, [0, 0.999]
  double reference_radius_mm = 100.0;  ///< an orientation error in rad counts as this lever arm
  RtestBasis basis;                    ///< of the joint fit
};

struct RtestDesignCandidate {
  RtestPattern pattern;
  bool feasible = false;
  std::string why_not;             ///< which limit, or which location error is not determined
  double duration_s = 0.0;         ///< poses x nests x dwell
  std::vector<std::string> names;  ///< the fit's parameters (location errors, maps, zeros)
  Eigen::VectorXd sigma;           ///< predicted 1 sigma at the budget (infinite: held by the fit)
  double worst_expanded_um =
      0.0;  ///< max over the location errors of 2 sigma (rad x reference radius)
  std::string worst_error;
};

struct RtestDesign {
  RtestDesignCandidate best;
  RtestDesignCandidate baseline;  ///< options.base, evaluated the same way
  double time_budget_s = 0.0;
  double ratio = 0.0;  ///< best / baseline worst expanded uncertainty
  std::vector<RtestDesignCandidate> candidates;
};

/// Evaluate one pattern at a time budget (0: its own run time). A pattern beyond the budget,
/// the travel or the B limits, or one whose fit cannot determine a location error or a map
/// coefficient (a grid too coarse for the basis fits a smaller model, not comparable), is
/// returned not feasible with the reason; never throws for those.
RtestDesignCandidate evaluate_rtest_design(const RtestPattern& pattern,
                                           const RtestDesignOptions& options, double time_budget_s);

/// Choose nests, then grid. Throws InvalidArgument naming the option for empty grids,
/// non-positive steps, noise, dwell or reference radius, rho outside [0, 0.999], reversed B
/// limits, or when no candidate is feasible (the message gives reasons).
RtestDesign design_rtest_test(const RtestDesignOptions& options);

// ------------------------------------------------------------------ separating two effects

/// Options of the added nest that separates two effects after an R-test session.
struct RtestSeparationOptions {
  /// Nest candidates (cylindrical about the C axis, table frame): distance from the C axis,
  /// angle from +X about +Z, height above the B axis.
  std::vector<double> nest_radius_mm = {0.0, 50.0, 100.0, 150.0};
  std::vector<double> nest_angle_deg = {0.0, 90.0, 180.0, 270.0};
  std::vector<double> nest_height_mm = {20.0, 60.0, 100.0, 140.0};
  std::vector<double> b_step_deg = {15.0, 30.0};  ///< grids of the added nest (C over a full turn)
  std::vector<double> c_step_deg = {30.0, 60.0};
  std::array<double, 2> b_limits_deg = {-90.0, 90.0};
  Eigen::Vector3d travel_min = Eigen::Vector3d(-400, -300, -300);
  Eigen::Vector3d travel_max = Eigen::Vector3d(400, 300, 400);
  double dwell_s = 0.0;  ///< per pose; 0: the session's (median time between poses)
  double max_added_time_s =
      600.0;  ///< the added nest's poses, repeated to gather data, take at most this
  double max_correlation = 0.5;
  double noise_um = 0.0;  ///< 0: the session's residual noise (R-test joint fit's noise model)
  double reference_radius_mm = 100.0;
};

struct RtestSeparatingCandidate {
  RtestPattern added;  ///< one nest and its grid
  std::string description;
  double duration_s = 0.0;  ///< poses x dwell
  double repeats = 1.0;     ///< the pattern run this many times to gather data
  double correlation =
      1.0;  ///< largest canonical correlation of the pair's determined parameters afterwards
  bool determined = false;  ///< every parameter of both effects is determined
};

/// The engine's result (design/separation.hpp) with the R-test's chosen nest. Parameters of
/// the joint fit (names): 8 location errors, the probe zero of each session nest ("zero_x#N"),
/// the two effects' parameters, and the added nest's probe zero (absent from sigma_before).
struct RtestSeparationDesign : SeparationResult {
  RtestSeparatingCandidate chosen;
};

/// The smallest added R-test nest (position and grid) whose readings, fitted jointly with
/// `session` (location errors and the pair's parameters shared, one probe zero per nest, the
/// readings of kinematics/effects.hpp), bring the largest canonical correlation of the pair
/// below options.max_correlation, and the predicted 1 sigma afterwards; or, when the pair moves
/// the table alike (table_motion_overlap), why no test can. The session's noise (sigma and
/// effective samples per reading) comes from the R-test joint fit's noise model (identify_joint
/// with its default maps); the session and the nest as run are fitted together by
/// identify_multi (multi/identify.hpp). Throws InvalidArgument naming the option for a pair that is
/// not two different effects of the machine, empty grids, a session without displacements, or
/// non-positive limits.
RtestSeparationDesign design_rtest_separation(const RtestSession& session,
                                              const std::vector<Effect>& pair,
                                              const RtestSeparationOptions& options = {});

}  // namespace rotacal
