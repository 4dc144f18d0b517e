// SPDX-License-Identifier: BSD-3-Clause
// The choice of a round's finding and how sure its name is: the best candidate that passes the
// tests and whose refit determines a parameter, its posterior weight among its rivals
// (rivals.hpp), the group the data cannot separate and the ambiguity it leaves.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

#include "model_member.hpp"
#include "rivals.hpp"
#include "search.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// The effect's observable free parameters in `refit` (v) and their covariance (C_ee) under
// noise treatment t: C the refit's covariance of its free parameters (the whitened Gram
// matrix's inverse), e the effect's. Empty where it has none.
std::pair<Eigen::VectorXd, Eigen::MatrixXd> effect_estimate(const ModelFit& refit,
                                                            const Effect& effect,
                                                            const NoiseTreatment& t) {
  const std::string id = effect.id();
  std::vector<Eigen::Index> free, mine;
  for (Eigen::Index j = 0; j < refit.jacobian.cols(); ++j) {
    if (refit.jacobian.col(j).squaredNorm() == 0.0) continue;
    const ParameterEstimate& p = refit.parameters[static_cast<std::size_t>(j)];
    if ((p.name == id || p.name.rfind(id + ".", 0) == 0) && p.observable)
      mine.push_back(static_cast<Eigen::Index>(free.size()));
    free.push_back(j);
  }
  if (mine.empty()) return {};
  Eigen::MatrixXd Jf(refit.jacobian.rows(), static_cast<Eigen::Index>(free.size()));
  for (std::size_t a = 0; a < free.size(); ++a)
    Jf.col(static_cast<Eigen::Index>(a)) = refit.jacobian.col(free[a]);
  const Eigen::MatrixXd Jw = t.whiten(Jf);
  const Eigen::MatrixXd C =
      (Jw.transpose() * Jw).ldlt().solve(Eigen::MatrixXd::Identity(Jf.cols(), Jf.cols()));
  const Eigen::Index k = static_cast<Eigen::Index>(mine.size());
  Eigen::MatrixXd Cee(k, k);
  Eigen::VectorXd v(k);
  for (Eigen::Index a = 0; a < k; ++a) {
    v[a] = refit
               .parameters[static_cast<std::size_t>(
                   free[static_cast<std::size_t>(mine[static_cast<std::size_t>(a)])])]
               .value;
    for (Eigen::Index b = 0; b < k; ++b)
      Cee(a, b) = C(mine[static_cast<std::size_t>(a)], mine[static_cast<std::size_t>(b)]);
  }
  return {v, Cee};
}

}  // namespace

// How many sigma from zero the best-determined combination of `effect`'s observable free
// parameters is in `refit`, under noise treatment t: sqrt(v^T C_ee^-1 v).
double determined_sigmas(const ModelFit& refit, const Effect& effect, const NoiseTreatment& t) {
  const auto [v, Cee] = effect_estimate(refit, effect, t);
  if (v.size() == 0) return 0.0;
  const double chi2 = v.dot(Cee.ldlt().solve(v));
  return std::isfinite(chi2) && chi2 > 0.0 ? std::sqrt(chi2) : 0.0;
}

// How many sigma from zero the best-determined single parameter of `effect` is: max |v_i| /
// sqrt(C_ii) (never more than determined_sigmas).
double parameter_sigmas(const ModelFit& refit, const Effect& effect, const NoiseTreatment& t) {
  const auto [v, Cee] = effect_estimate(refit, effect, t);
  double best = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (Cee(i, i) > 0.0 && std::isfinite(Cee(i, i)))
      best = std::max(best, std::abs(v[i]) / std::sqrt(Cee(i, i)));
  return best;
}

namespace {

// Why the first of `aliases` is not resolved (the sampling's words).
std::string unresolved_reason(const std::vector<Effect>& candidates,
                              const std::vector<std::string>& unresolved,
                              const std::vector<Alternative>& aliases) {
  for (std::size_t c = 0; c < candidates.size(); ++c)
    if (!aliases.empty() && candidates[c].id() == aliases.front().effect) return unresolved[c];
  return "";
}

// The field of a finding, weighed under one noise model (`common`, against the inputs `in` of the
// model before it), rescored with its columns (their signatures tell rivals apart): every
// observable candidate of the round within kFieldMargin of the chosen one at either Occam term,
// and every one that passed the BIC threshold. In coloured noise each candidate was scored under
// its own noise model, so the margin on those scores is only a guide: a harmonic whose own
// 1/f-like model whitened it away can be far from the chosen one there and the best under the
// chosen one's model (the R-test's tilt-axis harmonics in 1/f-like noise at 10x).
struct Field {
  std::vector<Score> scores;
  RivalJudgement judged;  // its pointers are into `scores`
};
Field weigh_field(const SearchContext& S, const Round& R, const Score& chosen,
                  const ModelFit& before, const EffectModel& before_effects,
                  const NoiseTreatment& common, const ScoringInputs& in) {
  const double n = static_cast<double>(before.residuals.size());
  std::vector<Effect> near;
  constexpr double kFieldMargin = 40.0;  // a weight of e^-20 at most, before tempering
  // Each score at its most favourable, the chosen one at its least: a candidate rescored under
  // its own walk (search_round.cpp) is tighter there than the rivals first scored under the
  // round's, and a rival far from it only so was left out of the field (h-pink9: a 10x
  // ballbar_thermal_drift named ballbar_length_offset alone, weight 1.00).
  const auto ci = static_cast<std::size_t>(&chosen - R.scores.data());
  const double chosen_bic = std::max(chosen.delta_bic, R.round_bic[ci]);
  for (std::size_t i = 0; i < R.scores.size(); ++i) {
    const Score& s = R.scores[i];
    const double d_bic = std::min(s.delta_bic, R.round_bic[i]) - chosen_bic;
    const double d_aic = d_bic - (s.k - chosen.k) * (std::log(n) - 2.0);
    if (&s == &chosen || std::min(d_bic, d_aic) < kFieldMargin ||
        s.delta_bic < S.options.min_delta_bic)
      near.push_back(s.effect);
  }
  const std::vector<SharedMatrix> near_jc =
      S.cache.candidate_jacobians(S.P, before_effects, before, near);
  Field F;
  F.scores.reserve(near.size());
  for (std::size_t i = 0; i < near.size(); ++i)
    F.scores.push_back(score(in, near[i], common.whiten(*near_jc[i]), S.options.min_visible_chi2));
  std::vector<const Score*> field;
  std::vector<double> field_bic;
  const Score* chosen_judged = &chosen;
  for (const Score& s : F.scores) {
    field.push_back(&s);
    field_bic.push_back(s.observable ? s.delta_bic : std::numeric_limits<double>::infinity());
    if (s.effect == chosen.effect && s.observable) chosen_judged = &s;
  }
  const double tempering = S.noise.W && S.model ? evidence_tempering(*S.model) : 1.0;
  F.judged = weigh_rivals(*chosen_judged, field, field_bic, n, tempering,
                          S.options.rival_correlation, S.options.min_weight,
                          explained_away(in, *chosen_judged, field, S.options.min_delta_bic,
                                         S.options.rival_correlation));
  return F;
}

// weigh_field under treatment t (coloured: with the stream levels as nuisance parameters if
// `with_levels`; white: the round's own inputs).
Field weigh_field_under(const SearchContext& S, const Round& R, const Score& chosen,
                        const ModelFit& before, const EffectModel& before_effects,
                        const NoiseTreatment& t, bool with_levels) {
  if (!S.noise.W) return weigh_field(S, R, chosen, before, before_effects, t, R.in);
  ScoringInputs in;
  in.Jfree = with_levels ? R.J_levels : R.in.Jfree;
  in.num_free = before.num_free + (with_levels ? R.levels_rank : 0);
  in.Q_w = orthonormal_basis_full_rank(t.whiten(in.Jfree));
  in.r_w = t.whiten(before.residuals);
  return weigh_field(S, R, chosen, before, before_effects, t, in);
}

// The rivals of a finding about the member the model holds instead of the search's pick
// (judged.group.front()): the same weights (posterior over the field), delta BIC and the
// correlation of the fitted signatures about `held`, the pick among them.
std::vector<Alternative> rivals_about(const RivalJudgement& judged, const Score& held,
                                      double held_delta_bic, const Field& field,
                                      const std::optional<Field>& loose) {
  const auto signature_of = [&](const std::string& id) -> const Eigen::VectorXd* {
    for (const Score& s : field.scores)
      if (s.effect.id() == id) return &s.signature;
    if (loose)
      for (const Score& s : loose->scores)
        if (s.effect.id() == id) return &s.signature;
    return nullptr;
  };
  const auto about_held = [&](Alternative a) {
    a.delta_bic -= held_delta_bic;
    if (const Eigen::VectorXd* sig = signature_of(a.effect);
        sig && sig->size() == held.signature.size())
      a.correlation = std::abs(correlation(*sig, held.signature));
    return a;
  };
  Alternative pick;
  pick.effect = judged.group.front()->effect.id();
  pick.weight = judged.weight;
  pick.in_group = true;
  std::vector<Alternative> out{about_held(pick)};
  const std::string id = held.effect.id();
  for (const Alternative& a : judged.rivals)
    if (a.effect != id) out.push_back(about_held(a));
  std::stable_sort(out.begin(), out.end(),
                   [](const Alternative& a, const Alternative& b) { return a.weight > b.weight; });
  return out;
}

}  // namespace

std::pair<double, double> cross_validated(const SearchContext& S, const Round& R,
                                          const Eigen::MatrixXd& X, const ModelFit& fit,
                                          const ModelFit& refit, const std::vector<int>& fold) {
  const DiagnosisOptions& options = S.options;
  // Blocks as long as the noise's correlation as the extended model leaves it: the model of
  // the current residuals takes an unmodelled drift for slow noise (AR(7) at 1.9 um of
  // 0.5 um AR(1) 0.9 readings with a Z drift on the probe, a correlation of 42 of 120
  // touches), and two blocks of half a session each fail any effect (the baseline, fitted on
  // half the poses, extrapolates badly).
  std::vector<int> own_fold;
  if (S.model) {
    const NoiseModel own =
        estimate_noise_model(S.P.groups(), S.P.times(), refit.residuals, options.noise);
    own_fold = cv_folds(S.P, options.cv_blocks, own.white() ? nullptr : &own);
  }
  const std::vector<int>& f = S.model ? own_fold : fold;
  const double before = cv_rms_um(R.in.Jfree, fit.residuals, f, options.cv_blocks);
  const double after = cv_rms_um(X, fit.residuals, f, options.cv_blocks);
  return {before, after};
}

Choice choose(const SearchContext& S, const Round& R, const ModelFit& fit,
              const EffectModel& effects, const std::vector<int>& fold, std::vector<bool>& done,
              Diagnosis& D) {
  const DiagnosisOptions& options = S.options;
  const double m_tests = std::max<double>(1.0, static_cast<double>(R.scores.size()));
  std::vector<const Score*> passing;
  for (const Score& s : R.scores)
    if (s.f_pvalue < options.alpha / m_tests && s.delta_bic < options.min_delta_bic)
      passing.push_back(&s);
  std::sort(passing.begin(), passing.end(),
            [](const Score* a, const Score* b) { return a->delta_bic < b->delta_bic; });

  // The first passing candidate that also predicts left-out blocks better and whose
  // parameters the nonlinear refit can determine.
  Choice out;
  for (const Score* s : passing) {
    EffectModel extended = effects;
    extended.effects.push_back(s->effect);
    const ModelFit& refit = S.cache.fit(S.P, extended);
    std::tie(out.cv_before, out.cv_after) = cross_validated(S, R, s->X, fit, refit, fold);
    if (!(out.cv_after < out.cv_before)) continue;
    if (!holds_at_correlation_bound(S, R, *s, fit, refit, m_tests)) continue;
    // A cause with no number is no finding: at least one combination of its parameters must
    // be determined, min_determined_sigma from zero in the refit (a polynomial's correlated
    // coefficients can be so jointly while none is alone), not merely estimable.
    const bool any_determined =
        determined_sigmas(refit, s->effect,
                          R.treatment_of[static_cast<std::size_t>(s - R.scores.data())]) >=
        options.min_determined_sigma;
    for (std::size_t c = 0; c < S.candidates.size(); ++c)
      if (S.candidates[c] == s->effect) done[c] = true;
    if (!any_determined) {
      D.unobservable.push_back(
          {s->effect.id(),
           "it reduces the residual, but once it is in the model none of its "
           "parameters can be determined from these readings (none reaches " +
               std::to_string(static_cast<int>(options.min_determined_sigma)) +
               " sigma: they trade off against the location errors and the other effects)"});
      continue;
    }
    out.chosen = s;
    out.refit = &refit;
    out.fold = &fold;
    return out;
  }
  return out;
}

std::optional<Finding> name_finding(const SearchContext& S, const Round& R, const Choice& choice,
                                    const ModelFit& before, const EffectModel& before_effects,
                                    Diagnosis& D) {
  const Score& chosen = *choice.chosen;
  const ModelFit& fit = *choice.refit;
  const double n = static_cast<double>(before.residuals.size());
  // How sure the name is: posterior weights against the candidates that explain the same
  // signal (rivals.hpp). Below min_weight the finding is the group the data cannot separate,
  // reported ambiguous. The field is every observable candidate of the round that could hold
  // any weight, passed or not (the one that failed the F-test or BIC by a little may still fit
  // as well as the chosen one). It is weighed under one noise model, in coloured noise the
  // chosen candidate's own (each candidate's own model is estimated after removing it: a
  // flexible one that takes some of the noise's low frequencies with it whitens its own
  // residual more, and its BIC flatters it against a rival judged under another model).
  const std::size_t ci = static_cast<std::size_t>(&chosen - R.scores.data());
  const Field field = weigh_field_under(S, R, chosen, before, before_effects,
                                        S.noise.W ? R.treatment_of[ci] : S.noise, R.levels_of[ci]);
  // A chosen candidate rescored under the marginal bound (search_round.cpp) is weighed under the
  // within-stream bound of the same walk too, and stands by the worse (rivals.hpp, worse_of):
  // under the marginal bound alone a 3x linear_scale_Y was named [linear_scale_X,
  // angular_error_BX, angular_error_AY], the truth 22 behind; under the within-stream one alone
  // a 10x ballbar_thermal_drift was [thermal_warmup_X, thermal_drift_X], the truth's signature
  // left too little correlated with the chosen one's once the levels were loose (h-pink10).
  const auto loose = R.named_under.find(ci);
  std::optional<Field> loose_field;
  if (loose != R.named_under.end())
    loose_field.emplace(weigh_field_under(S, R, chosen, before, before_effects, loose->second,
                                          !loose->second.full));
  const RivalJudgement judged_rivals =
      loose_field ? worse_of(field.judged, loose_field->judged) : field.judged;
  // A harmonic of an order the sampling cannot resolve takes, at the sampled angles, the
  // values of lower orders: a finding of a harmonic of that axis may be it, of its own kind or
  // another (on the R-test's 7 tilt angles an axial h4 came out as a tilt h3).
  std::vector<Alternative> aliases;
  for (std::size_t c = 0; c < S.candidates.size(); ++c) {
    const Effect& e = S.candidates[c];
    if (chosen.effect.harmonic > 0 && e.harmonic > 0 && e.axis == chosen.effect.axis &&
        !S.unresolved[c].empty()) {
      Alternative a;
      a.effect = e.id();
      a.in_group = true;
      a.aliased = true;
      aliases.push_back(a);
    }
  }
  if (judged_rivals.group.size() > 1 || !aliases.empty()) {
    Ambiguity amb;
    for (const Score* g : judged_rivals.group) amb.effects.push_back(g->effect.id());
    for (const Alternative& a : aliases) amb.effects.push_back(a.effect);
    amb.correlation = 1.0;
    for (const Alternative& a : judged_rivals.rivals)
      if (a.in_group) {
        amb.delta_bic = std::max(amb.delta_bic, a.delta_bic);
        amb.correlation = std::min(amb.correlation, a.correlation);
      }
    amb.separating_test =
        judged_rivals.group.size() > 1
            ? separating_test(S.P, before, chosen, *judged_rivals.group[1], S.noise.sigma_mm)
            : "a finer step of axis " + std::string(1, chosen.effect.axis) +
                  " resolves the higher orders (" +
                  unresolved_reason(S.candidates, S.unresolved, aliases) + ")";
    D.ambiguous.push_back(amb);
  }

  // The member the extended model holds (model_member.hpp); its numbers are the finding's.
  const HeldMember held = hold_member(S, R, judged_rivals, before, fit, before_effects);
  Finding F;
  F.model_reason = held.why;
  if (!held.member) {
    std::string members;
    for (const Score* g : judged_rivals.group)
      members += (members.empty() ? "" : ", ") + g->effect.id();
    D.unobservable.push_back({held.top->effect.id(), "one of " + members + ": " + held.why});
    return std::nullopt;
  }
  const Score& shown = *held.member;
  const ModelFit& shown_fit = *held.refit;
  F.effect = shown.effect;
  F.cause = shown.effect.cause();
  F.weight = held.weight;
  F.rivals = shown.effect == chosen.effect
                 ? judged_rivals.rivals
                 : rivals_about(judged_rivals, shown, held.delta_bic, field, loose_field);
  F.rivals.insert(F.rivals.end(), aliases.begin(), aliases.end());
  F.gain.rms_before_um = rms_um(before.residuals);
  F.gain.rms_after_um = rms_um(shown_fit.residuals);
  std::size_t si = ci;
  for (std::size_t i = 0; i < R.scores.size(); ++i)
    if (R.scores[i].effect == shown.effect) si = i;
  const NoiseTreatment& judged = R.treatment_of[si];
  const double rss_before = judged.whiten(before.residuals).squaredNorm();
  const double rss_after = std::max(judged.whiten(shown_fit.residuals).squaredNorm(), 1e-300);
  F.gain.delta_bic =
      n * std::log(rss_after / rss_before) + (shown_fit.num_free - before.num_free) * std::log(n);
  F.gain.cv_rms_before_um = choice.cv_before;
  F.gain.cv_rms_after_um = choice.cv_after;
  F.gain.f_pvalue = R.scores[si].f_pvalue;
  if (si != ci) {  // the held member's own cross-validation, on the search's blocks
    const Score& s = R.scores[si];
    Eigen::MatrixXd X = s.X;
    if (X.cols() == 0) {
      const std::vector<SharedMatrix> jc =
          S.cache.candidate_jacobians(S.P, before_effects, before, {s.effect});
      X.resize(R.in.Jfree.rows(), R.in.Jfree.cols() + s.k);
      X << R.in.Jfree, *jc.front() * s.directions;
    }
    std::tie(F.gain.cv_rms_before_um, F.gain.cv_rms_after_um) =
        cross_validated(S, R, X, before, shown_fit, *choice.fold);
  }
  for (const ParameterEstimate& b : before.parameters) {
    for (const ParameterEstimate& a : shown_fit.parameters) {
      if (a.name != b.name || !a.observable || !b.observable) continue;
      if (std::abs(a.value - b.value) > std::max(a.std, 1e-15))
        F.shifts.push_back({a.name, b.value, a.value, a.std, a.unit});
    }
  }
  return F;
}

}  // namespace rotacal::diagnosis_detail
