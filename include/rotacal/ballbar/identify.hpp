#pragma once
/// \file
/// Identification of the eight location errors from a single set-up ballbar session:
/// `identify_joint` fits the exact model (model.hpp) to every sample at once with Ceres;
/// `identify_paper` (identify_paper.hpp) is Flynn et al.'s geometric chain.

#include <optional>
#include <string>
#include <vector>

#include "rotacal/ballbar/model.hpp"

namespace rotacal {

/// One identified quantity. `observable == false` means the session's tests cannot determine
/// it: value and std are then meaningless and are not reported by the writers.
struct ParameterEstimate {
  std::string name;
  double value = 0.0;
  double std = 0.0;  ///< 1 sigma
  std::string unit;
  bool observable = true;
};

struct BallbarIdentification {
  std::string method;                 ///< "joint" or "paper"
  BallbarMachineModel model;          ///< identified machine (unobservable parts left nominal)
  std::vector<ParameterEstimate> parameters;  ///< 8 location errors, pivot x y z, then extras
  Eigen::MatrixXd covariance;         ///< in `parameters` order, 1-sigma^2
  std::vector<double> residuals;      ///< measured - model, mm, per sample (session order)
  /// d(model length)/d(parameter) at the solution, mm per parameter unit; one row per fitted
  /// sample (in session order of the samples used), columns in `parameters` order.
  Eigen::MatrixXd jacobian;
  std::vector<bool> fixed;            ///< per parameter: held at its start value
  double residual_rms_um = 0.0;
  double sigma_um = 0.0;              ///< noise level used for the covariance
  std::size_t n_samples = 0;
  bool converged = false;
  int iterations = 0;
  std::vector<std::string> unobservable;  ///< combinations the tests cannot see, in words
  std::vector<std::string> notes;         ///< assumptions and warnings for the report

  /// The estimate called `name`; throws InvalidArgument if there is none.
  const ParameterEstimate& parameter(const std::string& name) const;
};

struct JointFitOptions {
  bool fit_length_offset = false;  ///< add ballbar_length_offset dL to the unknowns
  EffectModel effects;             ///< extra effects to fit along (diagnosis); starts at 0
  std::vector<std::string> tests;  ///< fit only these test labels (empty: all)
  int max_iterations = 100;
  /// A direction in parameter space is unobservable when moving along it by plausible
  /// magnitudes (1 mm, 1 mrad) changes chi-square by less than this.
  double observability_min_chi2 = 1.0;
};

/// Joint least-squares fit of location errors + actual pivot (+ dL, + effects) to every
/// sample: residual_i = (L_model,i - L_i) / sigma, autodiff Jacobians. Starts from zero errors
/// and the nominal pivot. The 1-sigma covariance is (J^T J)^-1 s^2 with s^2 the residual
/// variance; parameters the tests cannot see are held at zero and reported as unobservable.
/// Throws InvalidArgument for a session with fewer samples than unknowns.
BallbarIdentification identify_joint(const BallbarSession& session,
                                     const JointFitOptions& options = {});

}  // namespace rotacal
