// SPDX-License-Identifier: BSD-3-Clause
// A joint identification of several sessions as a model document (multi/model_document.hpp).
#include "rotacal/multi/model_document.hpp"

#include <cstdio>

#include "rotacal/core/error.hpp"

namespace rotacal {

void refuse_disagreeing(const MultiIdentification& ident) {
  if (ident.disagreements.empty() || ident.sigma_inflated) return;
  std::string what;
  for (const MultiDisagreement& d : ident.disagreements) {
    if (what.size() > 600) {
      what += "; ...";
      break;
    }
    char z[32];
    std::snprintf(z, sizeof z, "%.1f", d.z);
    what += (what.empty() ? "" : "; ") + d.parameter + " (" + d.session_a + " vs " + d.session_b +
            ", z = " + z + ")";
  }
  throw InvalidArgument(
      "the sessions disagree: " + what +
      ". A joint model of sessions that disagree describes no machine, so it is not saved, "
      "stored or exported: find the session in error (another machine, a gross error), or "
      "ask for the sigmas to be widened by the sessions' scatter (identify --inflate-sigma)");
}

FittedModelContent multi_model_content(const MultiIdentification& ident) {
  const std::size_t n = ident.parameters.size();
  if (ident.covariance.rows() != static_cast<Eigen::Index>(n) ||
      ident.covariance.cols() != static_cast<Eigen::Index>(n))
    throw InvalidArgument("multi_model_content: the covariance is not " + std::to_string(n) +
                          " x " + std::to_string(n));
  const std::vector<ParameterEstimate> effects = ident.effects();
  if (effects.size() != static_cast<std::size_t>(ident.effect_model.num_params()))
    throw InvalidArgument("multi_model_content: " + std::to_string(effects.size()) +
                          " effect parameters, the effect model has " +
                          std::to_string(ident.effect_model.num_params()));
  refuse_disagreeing(ident);
  FittedModelContent c;
  c.kind = "multi";
  c.machine = ident.machine;
  c.location_errors = ident.location_errors();
  c.effects = ident.effect_model;
  c.effect_parameters = effects;
  for (const ParameterEstimate& p : ident.parameters) c.covariance_parameters.push_back(p.name);
  c.covariance = ident.covariance;
  for (const MultiSessionResult& r : ident.sessions) {
    FittedSessionContent s;
    s.name = r.name;
    s.instrument = r.instrument;
    s.nuisances = r.nuisances;
    s.alone = r.alone;
    s.noise = r.noise;
    s.noise_refit = r.noise_refit;
    s.noise_correction = r.noise_correction;
    s.residual_rms_um = r.residual_rms_um;
    s.n_residuals = r.n_residuals;
    c.sessions.push_back(std::move(s));
  }
  for (const MultiDisagreement& d : ident.disagreements)
    c.disagreements.push_back({d.parameter, d.unit, d.session_a, d.session_b, d.value_a, d.value_b,
                               d.difference, d.sigma, d.z});
  c.converged = ident.converged;
  c.chi2_per_dof = ident.summary.chi2_per_dof;
  c.unobservable = ident.unobservable;
  c.notes = ident.notes;
  c.sigma_inflated = ident.sigma_inflated;
  return c;
}

nlohmann::ordered_json multi_model_document(const MultiIdentification& ident) {
  return fitted_model_document(multi_model_content(ident));
}

}  // namespace rotacal
