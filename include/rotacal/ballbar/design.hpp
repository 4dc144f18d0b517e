// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Design of the single set-up ballbar test before the machine runs it: among pivot positions
/// and bar lengths that fit the machine's travel and rotary limits, the set-up whose joint fit
/// gives the smallest largest expanded uncertainty (k = 2) of the eight location errors at a
/// given run time, from the Fisher information of the joint model (the same Jacobian the fit
/// uses), with the effects of concern fitted alongside so that their correlation with the
/// location errors and with each other is known before the test.
///
/// Information at a run time: the recorder samples the tests at `sample_rate_hz`; running the
/// same path slower (all feeds scaled alike) to fill the time budget gives proportionally more
/// samples of the same geometry, so the information of a plan sampled every `step_deg` is
/// scaled by (samples recorded in the tests) / (plan samples). Correlated noise is taken as
/// AR(1) with coefficient `noise_rho` between recorded samples, i.e. (1 - rho) / (1 + rho)
/// effective samples per sample (the large-sample GLS information of a slowly varying model).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/plan.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/design/separation.hpp"
#include "rotacal/design/table_motion.hpp"
#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

struct BallbarDesignOptions {
  /// Machine, tests, ranges, feeds and radial side of every candidate; its pivot and bar
  /// length are the default design that the result is compared with.
  BallbarSetup base;
  std::vector<double> bar_lengths_mm = {100.0, 150.0};  ///< the bars available
  /// Pivot candidates: Flynn's O_x (distance from the C axis, along +X) and O_z (height above
  /// the tilt axis), table frame, mm; every pair on the grid is tried.
  std::vector<double> pivot_x_mm = {60.0, 90.0, 120.0, 150.0, 180.0};
  std::vector<double> pivot_z_mm = {20.0, 40.0, 60.0, 90.0, 120.0};
  /// Travel of the machine axes X, Y, Z in the frame of formats.md (origin at the nominal
  /// intersection of the rotary axes), mm: min and max per axis.
  Eigen::Vector3d travel_min = Eigen::Vector3d(-400, -300, -300);
  Eigen::Vector3d travel_max = Eigen::Vector3d(400, 300, 400);
  double time_budget_s = 0.0;          ///< 0: the default design's run time
  double sample_rate_hz = 100.0;       ///< of the recorder
  double noise_um = 0.5;               ///< 1 sigma per sample
  double noise_rho = 0.0;              ///< AR(1) coefficient between samples, [0, 0.999]
  double reference_radius_mm = 100.0;  ///< an orientation error in rad counts as this lever arm
  EffectModel effects_of_concern;      ///< fitted with the location errors in every candidate
};

struct DesignCandidate {
  BallbarSetup setup;
  bool feasible = false;
  std::string why_not;             ///< when not feasible: which limit, or what is unobservable
  double duration_s = 0.0;         ///< at the base feeds
  std::vector<std::string> names;  ///< the fit's parameters (location errors, pivot, effects)
  Eigen::VectorXd
      sigma;  ///< predicted 1 sigma at the time budget, parameter order; infinite: not determined
  double worst_expanded_um =
      0.0;  ///< max over the location errors of 2 sigma, um (rad x reference radius)
  std::string worst_error;  ///< its name
  /// Largest |correlation| of each effect parameter with any location error, and with the
  /// other effects' parameters, in effects_of_concern order.
  std::vector<double> effect_vs_location;
  std::vector<double> effect_vs_effects;
};

struct BallbarDesign {
  DesignCandidate best;
  DesignCandidate baseline;  ///< options.base, evaluated the same way
  double time_budget_s = 0.0;
  double ratio = 0.0;                       ///< best.worst_expanded_um / baseline.worst_expanded_um
  std::vector<DesignCandidate> candidates;  ///< every set-up tried, feasible or not
};

/// The first sample of `plan` whose machine axes leave the travel [lo, hi] (mm), in words;
/// empty if none does.
std::string travel_violation(const BallbarPlan& plan, const Eigen::Vector3d& lo,
                             const Eigen::Vector3d& hi);

/// Evaluate one set-up at a time budget (0: its own run time). Never throws for a set-up that
/// breaks a limit: the candidate says why it is not feasible.
DesignCandidate evaluate_design(const BallbarSetup& setup, const BallbarDesignOptions& options,
                                double time_budget_s);

/// Try every pivot and bar length. Throws InvalidArgument naming the option for an empty grid,
/// a non-positive rate, noise or reference radius, rho outside [0, 0.999], or when no candidate
/// is feasible (the message gives the reasons).
BallbarDesign design_ballbar_test(const BallbarDesignOptions& options);

// ------------------------------------------------------------------ separating two effects

/// Options of the added test that separates two effects after a session.
struct SeparationOptions {
  /// Step and feeds of the added test, and its C range; machine, pivot and bar length come
  /// from the session.
  BallbarSetup added;
  std::vector<double> bar_lengths_mm = {100.0, 150.0};  ///< the bars available
  /// Pivot candidates of a new set-up (cylindrical about the C axis, table frame): distance
  /// from the C axis, angle from +X about +Z, height above the tilt axis. A pivot on the C
  /// axis (radius 0) reads the axial motion of C with no lever arm for its tilt motion; the
  /// radial tests cannot be planned there and are left out.
  std::vector<double> pivot_radius_mm = {0.0, 60.0, 120.0, 180.0};
  std::vector<double> pivot_angle_deg = {0.0, 90.0};
  std::vector<double> pivot_z_mm = {20.0, 60.0, 120.0};
  Eigen::Vector3d travel_min =
      Eigen::Vector3d(-400, -300, -300);  ///< X, Y, Z, mm (formats.md frame)
  Eigen::Vector3d travel_max = Eigen::Vector3d(400, 300, 400);
  std::array<double, 2> tilt_limits_deg = {-90.0, 90.0};  ///< rotary limits of the tilt axis, deg
  double max_added_time_s =
      600.0;                     ///< the added test, slowed down to gather data, takes at most this
  double max_correlation = 0.5;  ///< target: largest canonical correlation of the pair
  /// 1 sigma per reading, um; 0: the session's residual noise (its noise model). The
  /// session's effective samples per reading (AR model) apply to the added test too.
  double noise_um = 0.0;
  double reference_radius_mm = 100.0;  ///< lever arm of the table-motion comparison
};

/// One added test, evaluated jointly with the session.
struct SeparatingCandidate {
  BallbarSetup setup;       ///< the added test (tests, pivot, bar, ranges)
  bool new_pivot = false;   ///< the pivot moved: the sphere tests locate it again
  std::string description;  ///< in words
  double duration_s = 0.0;  ///< run time at the base feeds
  double slow_down = 1.0;   ///< feeds divided by this to gather data (run time x this)
  /// Largest canonical correlation of the pair's determined parameters afterwards (1: an
  /// effect has none). A parameter is held as the joint fit holds it: one per combination
  /// that moving by plausible magnitudes changes chi-square by less than 1
  /// (analyse_observability, core/least_squares.hpp).
  double correlation = 1.0;
  bool determined = false;  ///< every parameter of both effects is determined
};

/// The engine's result (design/separation.hpp) with the ballbar's chosen test. Parameters of
/// the joint fit (names): 8 location errors, the session's pivot (3), the two effects'
/// parameters, and the added set-up's pivot (3) when it moved (absent from sigma_before).
struct SeparationDesign : SeparationResult {
  SeparatingCandidate chosen;  ///< the shortest that does; else the one of lowest correlation
};

/// The smallest additional ballbar test (same pivot: one rotary test at another bar length or
/// range; moved pivot: the sphere tests and one rotary test) whose readings, fitted jointly
/// with `session` (location errors and the effects shared, one pivot per set-up), bring the
/// largest canonical correlation between the parameters of `pair` below
/// options.max_correlation, and the predicted 1 sigma of every parameter afterwards. The
/// session's information is its joint-fit Jacobian (fit with the pair included) over its noise
/// (sigma and effective samples per reading from its AR noise model); the added test is read
/// as the session was (one reading per plan step) and slowing it down by s gathers s times the
/// readings. The session and the test as run are fitted together by identify_multi
/// (multi/identify.hpp; the test continues the session's set-up unless its pivot moved). When
/// the pair moves the table alike (table_motion_overlap) no test is searched:
/// the verdict says why. Throws InvalidArgument naming the option for a pair that is not two
/// different effects of the machine, empty grids, or non-positive limits.
SeparationDesign design_ballbar_separation(const BallbarSession& session,
                                           const std::vector<Effect>& pair,
                                           const SeparationOptions& options = {});

}  // namespace rotacal
