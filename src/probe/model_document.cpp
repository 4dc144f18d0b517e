// SPDX-License-Identifier: BSD-3-Clause
// A joint touch-probe identification as a model document (probe/model_document.hpp).
#include "rotacal/probe/model_document.hpp"

#include <set>

#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"

namespace rotacal {

FittedModelContent probe_model_content(const ProbeIdentification& ident,
                                       const std::string& session_name) {
  if (ident.method != "joint")
    throw InvalidArgument(
        "probe_model_content: the " + ident.method +
        " method gives no uncertainty or covariance; a model file holds the joint fit");
  const std::size_t n = ident.parameters.size();
  if (ident.covariance.rows() != static_cast<Eigen::Index>(n) ||
      ident.covariance.cols() != static_cast<Eigen::Index>(n))
    throw InvalidArgument("probe_model_content: the covariance is not " + std::to_string(n) +
                          " x " + std::to_string(n));
  FittedModelContent c;
  c.kind = "probe";
  c.machine = ident.model.machine;
  c.effects = ident.model.effects;
  for (const std::string& name : location_error_names(c.machine))
    c.location_errors.push_back(ident.parameter(name));
  std::set<std::string> shared(location_error_names(c.machine).begin(),
                               location_error_names(c.machine).end());
  for (const Effect& f : c.effects.effects)
    for (std::size_t k = 0; k < f.param_names().size(); ++k) {
      c.effect_parameters.push_back(ident.parameter(effect_parameter_name(f, k)));
      shared.insert(effect_parameter_name(f, k));
    }
  FittedSessionContent s;
  s.name = session_name;
  s.instrument = "probe";
  for (const ParameterEstimate& p : ident.parameters) {
    c.covariance_parameters.push_back(p.name);
    if (!shared.count(p.name)) s.nuisances.push_back(p);
  }
  s.noise = ident.noise;
  s.noise_refit = ident.noise_refit;
  s.noise_correction = ident.noise_correction;
  s.residual_rms_um = ident.residual_rms_um;
  s.n_residuals = ident.n_samples;
  c.sessions.push_back(std::move(s));
  c.covariance = ident.covariance;
  c.converged = ident.converged;
  c.chi2_per_dof = ident.summary.chi2_per_dof;
  c.unobservable = ident.unobservable;
  c.notes = ident.notes;
  return c;
}

nlohmann::ordered_json probe_model_document(const ProbeIdentification& ident,
                                            const std::string& session_name) {
  return fitted_model_document(probe_model_content(ident, session_name));
}

}  // namespace rotacal
