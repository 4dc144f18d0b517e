// SPDX-License-Identifier: BSD-3-Clause
// The one identification result of every instrument (core/identification.hpp).
#include "rotacal/core/identification.hpp"

#include <algorithm>
#include <cmath>

#include "rotacal/core/error.hpp"

namespace rotacal {

const ParameterEstimate& Identification::parameter(const std::string& name) const {
  for (const ParameterEstimate& p : parameters)
    if (p.name == name) return p;
  throw InvalidArgument("no identified parameter named '" + name + "'");
}

std::vector<ParameterEstimate> Identification::block(const std::string& name) const {
  const ParameterBlock& b = blocks.block(name);
  if (b.end() > static_cast<Eigen::Index>(parameters.size()))
    throw InvalidArgument("identification: block " + name + " lies outside the " +
                          std::to_string(parameters.size()) + " parameters");
  return {parameters.begin() + b.offset, parameters.begin() + b.end()};
}

Identification joint_identification(NoiseFit nf, ParameterLayout blocks, bool whitened,
                                    bool dof_corrected) {
  JointFitOutcome& fit = nf.fit;
  Identification out;
  out.method = "joint";
  out.blocks = std::move(blocks);
  out.converged = fit.summary.converged;
  out.iterations = fit.summary.iterations;
  out.residuals.assign(fit.residuals.data(), fit.residuals.data() + fit.residuals.size());
  const double n = static_cast<double>(fit.residuals.size());
  out.residual_rms_um = std::sqrt(fit.residuals.squaredNorm() / n) * 1e3;
  out.sigma_um = std::sqrt(fit.residual_variance) * 1e3;
  if (dof_corrected || whitened || nf.refit)  // the noise level the covariance rests on
    out.sigma_um =
        std::sqrt(fit.residuals.squaredNorm() / std::max(1.0, n - fit.summary.num_free)) * 1e3;
  out.covariance = std::move(fit.covariance);
  out.jacobian = std::move(fit.jacobian);
  for (bool f : fit.free) out.fixed.push_back(!f);
  out.parameters = std::move(fit.estimates);
  out.unobservable = std::move(fit.unobservable);
  out.summary = fit.summary;
  out.noise = std::move(nf.noise);
  out.noise_refit = nf.refit;
  out.noise_correction = nf.scale;
  return out;
}

std::string noise_refit_note(const NoiseFit& nf) {
  if (!nf.refit) return {};
  if (nf.reml)
    return "correlated noise (" + nf.noise.summary() +
           ", REML over the fit's residual space): covariance by GLS under this model";
  return "correlated noise (" + nf.noise.summary() +
         "): covariance by GLS under this AR model, scaled by " + std::to_string(nf.scale) +
         " for the correlation the fit absorbs from its residuals";
}

}  // namespace rotacal
