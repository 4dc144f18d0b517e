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

#include <string>
#include <vector>

#include <Eigen/Core>

#include "rotacal/ballbar/test_plan.hpp"
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
  double time_budget_s = 0.0;       ///< 0: the default design's run time
  double sample_rate_hz = 100.0;    ///< of the recorder
  double noise_um = 0.5;            ///< 1 sigma per sample
  double noise_rho = 0.0;           ///< AR(1) coefficient between samples, [0, 0.999]
  double reference_radius_mm = 100.0;  ///< an orientation error in rad counts as this lever arm
  EffectModel effects_of_concern;   ///< fitted with the location errors in every candidate
};

struct DesignCandidate {
  BallbarSetup setup;
  bool feasible = false;
  std::string why_not;           ///< when not feasible: which limit, or what is unobservable
  double duration_s = 0.0;       ///< at the base feeds
  std::vector<std::string> names;  ///< the fit's parameters (location errors, pivot, effects)
  Eigen::VectorXd sigma;           ///< predicted 1 sigma at the time budget, parameter order; infinite: not determined
  double worst_expanded_um = 0.0;  ///< max over the location errors of 2 sigma, um (rad x reference radius)
  std::string worst_error;         ///< its name
  /// Largest |correlation| of each effect parameter with any location error, and with the
  /// other effects' parameters, in effects_of_concern order.
  std::vector<double> effect_vs_location;
  std::vector<double> effect_vs_effects;
};

struct BallbarDesign {
  DesignCandidate best;
  DesignCandidate baseline;                ///< options.base, evaluated the same way
  double time_budget_s = 0.0;
  double ratio = 0.0;                      ///< best.worst_expanded_um / baseline.worst_expanded_um
  std::vector<DesignCandidate> candidates; ///< every set-up tried, feasible or not
};

/// Evaluate one set-up at a time budget (0: its own run time). Never throws for a set-up that
/// breaks a limit: the candidate says why it is not feasible.
DesignCandidate evaluate_design(const BallbarSetup& setup, const BallbarDesignOptions& options, double time_budget_s);

/// Try every pivot and bar length. Throws InvalidArgument naming the option for an empty grid,
/// a non-positive rate, noise or reference radius, rho outside [0, 0.999], or when no candidate
/// is feasible (the message gives the reasons).
BallbarDesign design_ballbar_test(const BallbarDesignOptions& options);

}  // namespace rotacal
