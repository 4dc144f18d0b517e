// SPDX-License-Identifier: BSD-3-Clause
// JointRefitter: refits of a joint fit's model on other readings (a Monte Carlo draw, a
// bootstrap resample), chord steps on the reference fit's Jacobian, falling back to a fresh
// solve_joint where that Jacobian no longer contracts the step.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "rotacal/core/joint_fit.hpp"
#include "rotacal/core/least_squares.hpp"

namespace rotacal {

JointRefitter::JointRefitter(const JointFitOutcome& reference, std::vector<FitParameter> parameters,
                             JointFitSettings settings)
    : start_(reference.values),
      parameters_(std::move(parameters)),
      settings_(std::move(settings)),
      convention_(reference.convention) {
  ROTACAL_ASSERT(static_cast<Eigen::Index>(parameters_.size()) == start_.size());
  for (std::size_t j = 0; j < reference.free.size(); ++j)
    if (reference.free[j]) idx_.push_back(static_cast<Eigen::Index>(j));
  const Eigen::Index q = static_cast<Eigen::Index>(idx_.size());
  Jw_free_.resize(reference.jacobian.rows(), q);
  for (Eigen::Index a = 0; a < q; ++a)
    Jw_free_.col(a) = reference.jacobian.col(idx_[static_cast<std::size_t>(a)]);
  if (settings_.whitener)
    settings_.whitener->apply(Jw_free_);
  else
    Jw_free_ /= settings_.sigma;
  ldlt_.compute(gram_matrix(Jw_free_));
  sigma_ = ldlt_.solve(Eigen::MatrixXd::Identity(q, q)).diagonal().cwiseMax(0.0).cwiseSqrt();
}

JointRefitter::Result JointRefitter::refit(const ResidualModel& model) const {
  Result res;
  res.values = start_;
  const Eigen::Index n = model.num_residuals();
  ROTACAL_ASSERT(n == Jw_free_.rows() && model.num_parameters() == start_.size());
  Eigen::VectorXd r(n);
  for (int it = 0; it < 20; ++it) {
    model.evaluate(res.values, r, nullptr);
    ++res.residual_evaluations;
    if (settings_.whitener)
      settings_.whitener->apply(r);
    else
      r /= settings_.sigma;
    const Eigen::VectorXd dx = -ldlt_.solve(Jw_free_.transpose() * r);
    double step = 0.0;
    for (Eigen::Index a = 0; a < dx.size(); ++a)
      if (sigma_[a] > 0.0) step = std::max(step, std::abs(dx[a]) / sigma_[a]);
    if (!std::isfinite(step)) break;
    for (Eigen::Index a = 0; a < dx.size(); ++a)
      res.values[idx_[static_cast<std::size_t>(a)]] += dx[a];
    if (step < settings_.step_tolerance_sigma) {
      res.converged = true;
      if (convention_.size()) res.values = convention_ * res.values;  // as the reference reports
      return res;
    }
  }
  // Too far from the reference for its Jacobian: a fresh fit.
  const JointFitOutcome fresh = solve_joint(model, parameters_, settings_);
  res.values = fresh.values;
  res.converged = fresh.summary.converged;
  res.residual_evaluations += fresh.summary.residual_evaluations;
  res.fell_back = true;
  return res;
}

}  // namespace rotacal
