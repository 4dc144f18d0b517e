// SPDX-License-Identifier: BSD-3-Clause
// The uncertainty budget of an R-test joint identification: the budget of its own model (location
// errors, tool_offset_Z on a head machine, the smooth error maps, probe zeros), not of the
// diagnosis' baseline, so that the values and type A it shows are the ones identify reports.
#include "rotacal/diagnose/rtest_budget.hpp"

#include <cmath>

#include "budget_detail.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/diagnose/rtest_diagnosis.hpp"
#include "rotacal/rtest/problem.hpp"

namespace rotacal {

namespace {

const ParameterEstimate& estimate_named(const RtestJointIdentification& id,
                                        const std::string& name) {
  for (const ParameterEstimate& p : id.parameters)
    if (p.name == name) return p;
  throw InvalidArgument("uncertainty_budget: the identification has no parameter " + name +
                        ": it is not of this session");
}

// The point of the diagnosis' model (location errors, tool_offset_Z, probe zeros; no maps) at
// the identification's values, where the candidates' columns are taken: the catalogue's first
// derivatives at zero effect hardly depend on the location errors, but the layout must be that
// model's.
ModelFit diagnosis_point(const RtestArrays& d, const RtestJointIdentification& id) {
  ModelFit at;
  const RtestLayout L = rtest_layout(d.machine, d.setups, nullptr, EffectModel{});
  for (const std::string& name : L.all.names()) at.parameters.push_back(estimate_named(id, name));
  return at;
}

}  // namespace

UncertaintyBudget uncertainty_budget(const RtestSession& session,
                                     const RtestJointIdentification& id,
                                     const PlausibleSizes& sizes, double coverage,
                                     int max_harmonic) {
  const RtestDiagnosisProblem problem(session);
  const std::vector<Effect> candidates = problem.candidates(max_harmonic);
  budget_detail::check_inputs(sizes, candidates, coverage);

  // The identification's model, evaluated again at its values for its Jacobian (not kept by
  // the identification); its residuals must be the identification's, or it is another session's.
  const RtestArrays data = rtest_arrays(session, "uncertainty_budget");
  const RtestProblem model(data, &id.model.basis, EffectModel{});
  const std::vector<std::string> names = model.layout().all.names();
  const auto p = static_cast<Eigen::Index>(names.size());
  if (id.parameters.size() != names.size() || id.covariance.rows() != p ||
      id.n_samples != session.samples.size() || id.residuals.size() != 3 * id.n_samples)
    throw InvalidArgument("uncertainty_budget: the identification is not of this session (" +
                          std::to_string(id.parameters.size()) + " parameters, " +
                          std::to_string(id.n_samples) + " samples; the session's model has " +
                          std::to_string(p) + " and " + std::to_string(session.samples.size()) +
                          ")");
  Eigen::VectorXd x(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const ParameterEstimate& e = id.parameters[static_cast<std::size_t>(j)];
    if (e.name != names[static_cast<std::size_t>(j)])
      throw InvalidArgument("uncertainty_budget: the identification's parameter " +
                            std::to_string(j) + " is " + e.name + ", the session's model has " +
                            names[static_cast<std::size_t>(j)]);
    x[j] = e.value;
  }
  ModelFit fit;
  fit.parameters = id.parameters;
  Eigen::VectorXd r(model.num_residuals());
  fit.jacobian.setZero(model.num_residuals(), p);  // evaluate() fills a Jacobian of this size
  model.evaluate(x, r, &fit.jacobian);
  fit.residuals = -r;  // measured - model
  for (std::size_t i = 0; i < id.n_samples; ++i)
    if ((fit.residuals.segment<3>(3 * static_cast<Eigen::Index>(i)) - id.residual(i))
            .cwiseAbs()
            .maxCoeff() > 1e-9)
      throw InvalidArgument("uncertainty_budget: the identification's residual of sample " +
                            std::to_string(i + 1) +
                            " is not the session's: it is another session's identification");
  // Held parameters (fixed, or directions the session cannot see) take no part.
  for (Eigen::Index j = 0; j < p; ++j)
    if (!fit.parameters[static_cast<std::size_t>(j)].observable || !(id.covariance(j, j) > 0.0))
      fit.jacobian.col(j).setZero();
  fit.num_free = static_cast<int>((fit.jacobian.colwise().squaredNorm().array() > 0.0).count());

  const NoiseModel white;  // without the GLS refit the identification's covariance is the white one
  const budget_detail::BudgetedFit budgeted{
      session.machine, fit, id.noise_refit ? id.noise : white, id.sigma_um, &id.covariance,
      problem.times()};
  const ModelFit at = diagnosis_point(data, id);
  return budget_detail::budget_of(
      budgeted, candidates,
      [&](const budget_detail::JacobianVisitor& v) {
        problem.visit_candidate_jacobians(at, candidates, v);
      },
      sizes, coverage);
}

}  // namespace rotacal
