// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: the uncertainty budget of any fitted model, shared by the budget of
// a diagnosis' final model (uncertainty_budget.cpp) and that of an identification whose model is
// not the diagnosis' (the R-test's smooth error maps: rtest_budget.cpp).

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "rotacal/diagnose/uncertainty_budget.hpp"

namespace rotacal::budget_detail {

/// The model a budget is of.
struct BudgetedFit {
  MachineType machine;
  const ModelFit& fit;      ///< parameters (the location errors by name), residuals, free columns
  const NoiseModel& noise;  ///< of fit.residuals (white: sigma noise_um)
  double noise_um;
  /// Type A covariance in fit.parameters order, as the fit reports it; nullptr: (J_w^T J_w)^-1.
  const Eigen::MatrixXd* covariance;
  const std::vector<double>& times;  ///< per reading (s): the session's duration sizes drifts
};

/// Throws InvalidArgument for a coverage outside (0, 1) or an override naming none of `all`.
void check_inputs(const PlausibleSizes& sizes, const std::vector<Effect>& all, double coverage);

/// Hands each candidate's Jacobian (d reading / d effect parameter, mm per unit, rows as
/// m.fit's) to the visitor with its index: DiagnosisProblem::visit_candidate_jacobians.
using JacobianVisitor = std::function<void(std::size_t, const Eigen::MatrixXd&)>;
using CandidateJacobians = std::function<void(const JacobianVisitor&)>;

/// The budget of m's location errors against the left-out `candidates`, whose Jacobians
/// `jacobians` visits, one at a time (a long session never holds them all).
UncertaintyBudget budget_of(const BudgetedFit& m, const std::vector<Effect>& candidates,
                            const CandidateJacobians& jacobians, const PlausibleSizes& sizes,
                            double coverage);

}  // namespace rotacal::budget_detail
