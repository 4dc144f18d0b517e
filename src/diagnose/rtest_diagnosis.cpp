// SPDX-License-Identifier: BSD-3-Clause
// The R-test diagnosis problem: baseline + effects fitted through the joint-fit driver on the
// one R-test reading (rtest/model.hpp), and the candidates' Jacobians by Jets of it.
#include "rotacal/diagnose/rtest_diagnosis.hpp"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "candidate_jets.hpp"
#include "rotacal/core/time_constant_fit.hpp"
#include "rotacal/rtest/problem.hpp"

namespace rotacal {

RtestDiagnosisProblem::RtestDiagnosisProblem(RtestSession session) : session_(std::move(session)) {
  arrays_ = std::make_shared<const RtestArrays>(rtest_arrays(session_, "diagnose_rtest"));
  for (const RtestSample& s : session_.samples)
    for (int k = 0; k < 3; ++k) {
      groups_.push_back("nest " + s.setup);
      times_.push_back(s.time);
      angles_.push_back(s.angles_rad());
    }
}

std::vector<Effect> RtestDiagnosisProblem::candidates(int max_harmonic) const {
  std::vector<Effect> out;
  // On a head machine tool_offset_Z is in the baseline (a location parameter of the head).
  const bool head = session_.machine.has_head();
  for (const Effect& e : effect_catalogue(session_.machine, max_harmonic))
    // The probes read static poses: the effects of the motion itself are zero there.
    if (e.kind != EffectKind::ballbar_length_offset &&
        e.kind != EffectKind::ballbar_thermal_drift &&
        !(head && e.kind == EffectKind::tool_offset_Z) && !e.depends_on_motion())
      out.push_back(e);
  return out;
}

ModelFit RtestDiagnosisProblem::fit_gls(const EffectModel& effects,
                                        std::shared_ptr<const ResidualWhitener> noise) const {
  // Location errors, tool_offset_Z on a head machine, probe zeros and the effects, all from
  // zero; the catalogue effects yield to the baseline where they share directions with it
  // (core/yield_convention.hpp: a first-order wobble of C is half an axis tilt).
  const RtestProblem model(*arrays_, nullptr, centred_on(effects, session_.samples));
  const EffectModel& fx = model.effects();
  const RtestLayout& L = model.layout();
  const std::vector<std::string> names = L.all.names(), units = L.all.units();
  std::vector<FitParameter> params;
  for (Eigen::Index j = 0; j < L.all.size(); ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    params.push_back({names[k], units[k], 0.0, 0.0, false, L.effects.contains(j)});
  }
  JointFitSettings settings;
  settings.sigma = session_.noise_um.value_or(1.0) * 1e-3;
  settings.whitener = std::move(noise);
  JointFitOutcome fit = solve_with_time_constants(model, params, settings);

  ModelFit out;
  out.effects = fx;
  out.residuals = std::move(fit.residuals);  // measured - model
  out.jacobian = std::move(fit.jacobian);
  out.num_free = fit.summary.num_free;
  std::vector<bool> held(fit.free.size());
  for (std::size_t j = 0; j < fit.free.size(); ++j) held[j] = !fit.free[j];
  out.hold(held);
  out.parameters = std::move(fit.estimates);
  return out;
}

namespace {

// d reading / d (the seeded parameters of `candidate`), three rows per pose: Jets of width N
// through the problem's one residual, the current model's values as constants, the candidate
// appended with its parameters at 0 (candidate_jets.hpp). The probe zeros and the measured
// readings are additive: they do not change the derivative.
template <int N>
Eigen::MatrixXd reading_jets(const RtestArrays& d, const ModelFit& at, const Effect& candidate,
                             const std::vector<int>& seed) {
  using Jet = ceres::Jet<double, N>;
  EffectModel fx = at.effects;
  fx.effects.push_back(candidate);
  const RtestLayout L = rtest_layout(d.machine, d.setups, nullptr, fx);
  std::vector<Jet> p(static_cast<std::size_t>(L.all.size()), Jet(0.0));
  for (std::size_t i = 0; i < at.parameters.size(); ++i) p[i] = Jet(at.parameters[i].value);
  const std::size_t first = at.parameters.size();  // the candidate's parameters: the layout's last
  for (std::size_t k = 0; k < seed.size(); ++k)
    p[first + static_cast<std::size_t>(seed[k])] = Jet(0.0, static_cast<int>(k));
  Eigen::MatrixXd out(3 * d.size(), static_cast<Eigen::Index>(seed.size()));
  for (Eigen::Index r = 0; r < d.size(); ++r) {
    const Vec3<Jet> res = rtest_residual<Jet>(L, d, fx, p.data(), r);
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < seed.size(); ++k)
        out(3 * r + a, static_cast<Eigen::Index>(k)) = res[a].v[static_cast<Eigen::Index>(k)];
  }
  return out;
}

}  // namespace

// jets(width, effect, seed) for candidate_jets.hpp.
auto RtestDiagnosisProblem::jets_at(const ModelFit& at) const {
  return [this, &at](auto width, const Effect& effect, const std::vector<int>& seed) {
    return reading_jets<decltype(width)::value>(*arrays_, at, effect, seed);
  };
}

Eigen::MatrixXd RtestDiagnosisProblem::candidate_jacobian(const ModelFit& at,
                                                          const Effect& candidate) const {
  return candidate_jacobians(at, {candidate}).front();
}

std::vector<Eigen::MatrixXd> RtestDiagnosisProblem::candidate_jacobians(
    const ModelFit& at, const std::vector<Effect>& candidates) const {
  return diagnosis_detail::jacobians_of_candidates(
      session_.machine, candidates, jets_at(at),
      [&](Eigen::Index row) { return arrays_->angles[static_cast<std::size_t>(row / 3)]; });
}

Eigen::MatrixXd RtestDiagnosisProblem::candidate_jacobian_by_jets(const ModelFit& at,
                                                                  const Effect& candidate) const {
  return diagnosis_detail::jets_of_width(candidate, diagnosis_detail::all_parameters(candidate),
                                         jets_at(at));
}

Diagnosis diagnose_rtest(const RtestSession& session, const DiagnosisOptions& options) {
  return diagnose(RtestDiagnosisProblem(session), options);
}

}  // namespace rotacal
