// SPDX-License-Identifier: BSD-3-Clause
// The diagnosis search loop and its entry point: baseline fit, candidates scored round by round
// (search_round.cpp), the best significant one added and the model refitted (selection.cpp),
// then what is left (final_test.cpp); in correlated noise, the final model's numbers by GLS.
#include "rotacal/diagnose/diagnosis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "model_member.hpp"
#include "rotacal/ballbar/plan.hpp"
#include "rotacal/core/stats.hpp"
#include "search.hpp"

namespace rotacal {

using namespace diagnosis_detail;

namespace diagnosis_detail {

// The effect's parameters in a fit (named "id" or "id.name").
std::vector<ParameterEstimate> parameters_of(const ModelFit& fit, const Effect& effect) {
  std::vector<ParameterEstimate> out;
  const std::string id = effect.id();
  for (const ParameterEstimate& p : fit.parameters)
    if (p.name == id || p.name.rfind(id + ".", 0) == 0) out.push_back(p);
  return out;
}

// One indicator column per noise stream (group, channel).
// One level per noise stream, shared by the runs of one test (radial_C, radial_C_cw,
// radial_C_f2000, test_of_run): they follow each other with the bar in place, so a wander does
// not start afresh between them, and a step between them (backlash, servo lag) is a signal.
// A label is taken for a run only where the test it names is itself a group of the session
// (a user's "sphere_f1" or an R-test set-up "nest_cw" keeps its own level).
Eigen::MatrixXd stream_levels(const DiagnosisProblem& P) {
  const auto streams = noise_streams(P.groups(), P.times());
  const std::set<std::string> groups(P.groups().begin(), P.groups().end());
  std::map<std::string, int> column;  // test of the stream's group, and its k-th stream there
  std::map<std::string, int> seen;
  std::vector<int> col_of(streams.size());
  for (std::size_t s = 0; s < streams.size(); ++s) {
    const std::string& g = P.groups()[static_cast<std::size_t>(streams[s].front())];
    const std::string test = test_of_run(g);
    const std::string key = (groups.count(test) ? test : g) + "#" + std::to_string(seen[g]++);
    const auto it = column.emplace(key, static_cast<int>(column.size())).first;
    col_of[s] = it->second;
  }
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(P.groups().size()),
                                            static_cast<Eigen::Index>(column.size()));
  for (std::size_t s = 0; s < streams.size(); ++s)
    for (Eigen::Index i : streams[s]) L(i, col_of[s]) = 1e-3;  // 1 um
  return L;
}

NoiseTreatment white_treatment(const DiagnosisProblem& P, const ModelFit& baseline) {
  NoiseTreatment t;
  if (const std::optional<double> declared = P.declared_noise_um()) {
    t.sigma_mm = *declared * 1e-3;
    t.source = "declared";
  } else {
    t.sigma_mm = estimate_noise_um(P, baseline.residuals) * 1e-3;
    t.source = "estimated from successive differences";
  }
  return t;
}

// The diagnosis judges slow signatures (harmonics over a test, drifts) against the noise's
// long-run variance, which the mean-removal bias of each stream's AR(1) coefficient makes too
// small near rho = 1 (10 false findings in 100 AR(1) rho 0.95 null sessions without the
// correction, 3 with it: bench/diagnose_realistic_bench).
NoiseTreatment coloured_treatment(const NoiseModel& estimated, bool described) {
  const NoiseModel m = with_mean_bias_corrected(estimated);
  NoiseTreatment t;
  t.sigma_mm = m.sigma_um * 1e-3;
  t.W = std::make_shared<ArWhitener>(m);
  if (described) t.source = "AR noise model of the residuals: " + m.summary();
  return t;
}

}  // namespace diagnosis_detail

namespace {

std::vector<Effect> candidate_list(const DiagnosisProblem& P, const DiagnosisOptions& options) {
  std::vector<Effect> candidates = P.candidates(options.max_harmonic);
  if (options.only.empty()) return candidates;
  std::vector<Effect> keep;
  for (const std::string& id : options.only) {
    const Effect e = Effect::parse(id);
    if (std::find(candidates.begin(), candidates.end(), e) == candidates.end())
      throw InvalidArgument("options.only: " + id + " is not a candidate for this session");
    keep.push_back(e);
  }
  return keep;
}

// A *_hn candidate of an order its axis' sampling cannot resolve takes, at the sampled angles,
// the values of lower orders (C every 30 deg: order 7 is order 5): scored, it would name an
// order the data cannot tell. Judged on every reading's angle of that axis, since the effect's
// parameters are shared by all of them. Returns the reason per candidate (empty: resolved).
std::vector<std::string> unresolved_orders(const DiagnosisProblem& P,
                                           const std::vector<Effect>& candidates,
                                           double min_new_content) {
  std::vector<std::string> unresolved(candidates.size());
  std::map<char, int> top;
  for (const Effect& c : candidates)
    if (c.harmonic > 0) top[c.axis] = std::max(top[c.axis], c.harmonic);
  for (const auto& [axis, order] : top) {
    std::vector<double> th;
    for (const RotaryAngles<double>& r : P.angles()) th.push_back(axis == 'C' ? r.rot : r.tilt);
    const HarmonicResolution res = resolve_harmonics(th, axis, order, min_new_content);
    for (std::size_t c = 0; c < candidates.size(); ++c)
      if (candidates[c].axis == axis && candidates[c].harmonic > res.resolved)
        unresolved[c] = "the sampling cannot resolve its harmonic order: " +
                        res.why_not(candidates[c].harmonic);
  }
  return unresolved;
}

// The search: score every candidate against the current model, add the best one that passes
// the F-test (Bonferroni), BIC and blocked cross-validation and whose parameters the refit can
// determine, refit, repeat. What is left is judged by the caller (judge_kept), once it keeps
// the result.
Diagnosis search(const DiagnosisProblem& P, const DiagnosisOptions& options,
                 const std::vector<Effect>& candidates, const ModelFit& baseline,
                 const NoiseTreatment& noise, const NoiseModel* model, const NoiseTreatment& white,
                 SearchCache& cache) {
  Diagnosis D;
  D.machine = P.machine();
  // The current model's fit: the baseline's, then a refit held by the cache (never copied: a
  // fit holds an n x p Jacobian).
  const ModelFit* fit = &baseline;
  // What callers read of the baseline fit: residuals and parameters (not its n x p Jacobian).
  D.baseline_fit.effects = fit->effects;
  D.baseline_fit.parameters = fit->parameters;
  D.baseline_fit.residuals = fit->residuals;
  D.baseline_fit.num_free = fit->num_free;
  const double n = static_cast<double>(fit->residuals.size());
  D.baseline.noise_um = noise.sigma_mm * 1e3;
  D.baseline.noise_source = noise.source;
  D.baseline.residual_rms_um = rms_um(fit->residuals);
  D.baseline.n = fit->residuals.size();
  D.baseline.dof = static_cast<int>(n) - fit->num_free;
  const double chi2 = noise.whiten(fit->residuals).squaredNorm();
  D.baseline.chi2_per_dof = chi2 / D.baseline.dof;
  D.baseline.p_value = stats::chi2_sf(chi2, D.baseline.dof);
  D.structure_before = residual_structure(P, fit->residuals);
  D.noise_whitened = static_cast<bool>(noise.W);

  const std::vector<std::string> unresolved =
      unresolved_orders(P, candidates, options.min_harmonic_new_content);
  const NoiseStreamLayout layout(P.groups(), P.times());  // every noise model of this search
  const SearchContext S{P, options, candidates, unresolved, noise, model, white, layout, cache};
  const std::vector<int> fold = cv_folds(P, options.cv_blocks, noise.W ? model : nullptr);
  EffectModel effects;
  effects.linear_reference = P.mean_commanded_xyz();
  // The search goes on from its picks, the model reports the held members (model_member.hpp):
  // so the later rounds, and every name, are the same whichever member is held (holding
  // another one before the next round left structure its pick explained: a radial_motion_C_h3
  // + linear_scale_X ballbar named straightness_ZX alone, tests/cpp/test_diagnose_ballbar.cpp).
  EffectModel picks = effects;
  std::vector<bool> done(candidates.size(), false);
  bool first_round = true;
  while (static_cast<int>(D.findings.size()) < options.max_findings) {
    const Round R = score_round(S, *fit, picks, done, first_round, D);
    first_round = false;
    const Choice choice = choose(S, R, *fit, picks, fold, done, D);
    if (!choice.chosen) break;
    const EffectModel before_effects = picks;
    std::optional<Finding> F = name_finding(S, R, choice, *fit, before_effects, D);
    if (!F) continue;  // no member of its group determined: the model holds the baseline
    for (std::size_t c = 0; c < candidates.size(); ++c)
      if (candidates[c] == F->effect) done[c] = true;
    effects.effects.push_back(F->effect);
    picks.effects.push_back(choice.chosen->effect);
    fit = &cache.fit(P, picks);
    D.findings.push_back(std::move(*F));
  }

  const ModelFit& held = effects.effects.empty() ? *fit : cache.fit(P, effects);
  for (Finding& F : D.findings) F.parameters = parameters_of(held, F.effect);
  D.final_fit = held;
  cache.picks = std::move(picks);
  return D;
}

// The fit of the search's picks (SearchCache::picks): D's final one where the model holds every
// pick.
const ModelFit& picks_fit(const DiagnosisProblem& P, SearchCache& cache, const Diagnosis& D) {
  bool same = cache.picks.effects.size() == D.findings.size();
  for (std::size_t i = 0; same && i < D.findings.size(); ++i)
    same = cache.picks.effects[i] == D.findings[i].effect;
  return same ? D.final_fit : cache.fit(P, cache.picks);
}

// What the final model of the search that gave D leaves, judged under that search's noise
// (judge_remainder), for the one search whose result is kept: a search that is then discarded
// (the white one redone with a better sigma, the coloured one whose final residuals are white)
// decided nothing by it. Judged on the fit the cache holds, D.final_fit (a copy of it) released
// meanwhile and copied again after: the structure test's peak has no second n x p Jacobian.
void judge_kept(const DiagnosisProblem& P, const DiagnosisOptions& options,
                const ModelFit& baseline, const NoiseTreatment& noise, const NoiseModel* model,
                const NoiseTreatment& white, SearchCache& cache, Diagnosis& D) {
  EffectModel effects;
  effects.linear_reference = P.mean_commanded_xyz();
  for (const Finding& F : D.findings) effects.effects.push_back(F.effect);
  const ModelFit& final_fit = effects.effects.empty() ? baseline : cache.fit(P, effects);
  const NoiseStreamLayout layout(P.groups(), P.times());
  const std::vector<Effect> no_candidates;  // the remainder's test scores no candidate
  const std::vector<std::string> no_reasons;
  const SearchContext S{P, options, no_candidates, no_reasons, noise, model, white, layout, cache};
  D.final_fit = ModelFit{};
  judge_remainder(S, final_fit, D);
  D.final_fit = final_fit;
}

// White treatment, redone once with the extended model's residual when successive
// differences overestimated the noise (sparse sampling against the systematic errors, as an
// R-test's 30 degree steps): if the extended model leaves less, that is the better estimate.
Diagnosis search_white(const DiagnosisProblem& P, const DiagnosisOptions& options,
                       const std::vector<Effect>& candidates, const ModelFit& baseline,
                       SearchCache& cache) {
  const NoiseTreatment white = white_treatment(P, baseline);
  Diagnosis D = search(P, options, candidates, baseline, white, nullptr, white, cache);
  NoiseTreatment kept = white;
  if (!P.declared_noise_um()) {
    const ModelFit& picked = picks_fit(P, cache, D);
    const double n = static_cast<double>(picked.residuals.size());
    const double s_final =
        std::sqrt(picked.residuals.squaredNorm() / std::max(1.0, n - picked.num_free)) * 1e3;
    if (s_final < 0.8 * D.baseline.noise_um) {
      NoiseTreatment better;
      better.sigma_mm = s_final * 1e-3;
      std::ostringstream why;
      why.precision(3);
      why << "estimated from the residuals of the extended model (successive differences gave "
          << D.baseline.noise_um << " um: the sampling is too sparse for them)";
      better.source = why.str();
      D = search(P, options, candidates, baseline, better, nullptr, better, cache);
      kept = better;
    }
  }
  judge_kept(P, options, baseline, kept, nullptr, kept, cache, D);
  return D;
}

// The findings' numbers by GLS under `gls_noise`, the covariance scaled by the whitened
// chi-square per dof where that exceeds 1. A finding none of whose parameters is then
// determined (min_determined_sigma, as in the search) is no finding (issue 29 item 6). The
// findings were chosen one after the other, each given the ones before it, so the last is
// dropped (reported unobservable) and the rest refitted until every finding is determined:
// the longest such prefix. Dropping the first undetermined finding and all after it lost real
// effects whose later, nearly aliased rival made both undetermined together (a 10x gravity sag
// of A on the probe in AR(1) 0.9 found as linear_scale_Z, 56 sigma alone, then a second A
// shape: 'nothing').
//
// Where the model holds what the weights say (hold_by_weight), a finding's held member must have
// a single parameter determined (model_member.hpp): one that has not, in a group with other
// scored members, is put in `not_held` and the caller runs the search again without holding it.
void refit_findings(const DiagnosisProblem& P, const DiagnosisOptions& options,
                    const NoiseTreatment& gls_noise, Diagnosis& D,
                    std::set<std::string>& not_held) {
  for (;;) {
    EffectModel found;
    found.linear_reference = P.mean_commanded_xyz();
    for (const Finding& F : D.findings) found.effects.push_back(F.effect);
    D.final_fit = P.fit_gls(found, gls_noise.full ? gls_noise.full : gls_noise.W);
    const double scale =
        std::sqrt(std::max(1.0, gls_noise.whiten(D.final_fit.residuals).squaredNorm() /
                                    std::max(1.0, static_cast<double>(D.final_fit.residuals.size() -
                                                                      D.final_fit.num_free))));
    const auto determined = [&](const Finding& F) {
      const double k = options.hold_by_weight ? parameter_sigmas(D.final_fit, F.effect, gls_noise)
                                              : determined_sigmas(D.final_fit, F.effect, gls_noise);
      return k / scale >= options.min_determined_sigma;
    };
    bool last_determined = true, may_pass_over = true;
    if (std::all_of(D.findings.begin(), D.findings.end(), determined)) {
      profile_time_constants(P, gls_noise, scale, D);
      for (Finding& F : D.findings) {
        F.parameters = parameters_of(D.final_fit, F.effect);
        for (ParameterEstimate& q : F.parameters) q.std *= scale;
      }
      if (!options.hold_by_weight || all_determined_as_reported(options, D)) return;
      // A warm-up whose tau the profile leaves open beside a drift (both undetermined: a BC-trt
      // probe's Y shift settling back, thermal_warmup_Y d = -2.6 mm beside thermal_drift_Y
      // 0.43 +- 0.25 um/s): the model holds neither; the last is dropped, as below.
      last_determined = reported_sigmas(D.findings.back()) >= options.min_determined_sigma;
      may_pass_over = earlier_determined_as_reported(options, D);
    } else {
      last_determined = determined(D.findings.back());
    }
    drop_last_finding(options, last_determined, "GLS under the noise the final model leaves", D,
                      not_held, may_pass_over);
  }
}

// The numbers of the final model by GLS under the noise the final model leaves (`model`): the
// white fit's covariance of AR(1) 0.9 readings is some 4x too small (2-sigma coverage of the
// ballbar's findings 32 %, bench/diagnosis_confusion.py). The noise for it by REML over what the
// fit leaves (Burg on the residuals misses the slow noise the fitted directions took: 84 % with
// it, 89 % by REML), with the stream levels it cannot show (HiddenLevels). REML's model is taken
// as it is: coloured_treatment's small-sample correction of an AR(1) coefficient,
// +(1 + 3 rho) / n, is Burg's bias on the residuals, which REML's restricted likelihood has
// already removed. Added again it raised an R-test stream's rho from 0.90 to 0.94: under the true
// rho the sigmas were 0.75 of the true-covariance GLS ones (1.00 without it); by REML on the
// ballbar (where it applies most, REML seldom keeping a walk there) a median 1.085 of the sigmas
// under the true noise model (1.005 without it; bench/diagnosis_confusion.py cells, AR(1) 0.9).
void final_gls(const DiagnosisProblem& P, const DiagnosisOptions& options, const NoiseModel& model,
               Diagnosis& D, std::set<std::string>& not_held) {
  if (D.findings.empty()) return;
  const NoiseModel reml =
      estimate_noise_model_reml(model, D.final_fit.residuals, free_columns(D.final_fit.jacobian));
  NoiseTreatment gls_noise;
  gls_noise.sigma_mm = reml.sigma_um * 1e-3;
  gls_noise.W = std::make_shared<ArWhitener>(reml);
  with_hidden_levels(P, reml, gls_noise);
  refit_findings(P, options, gls_noise, D, not_held);
}

// A white diagnosis' held time constants profiled (time_constants.cpp) where no refit did it,
// under white noise of the final fit's residual variance.
// Where the model holds what the weights say, a finding the profile leaves undetermined is
// dropped as refit_findings drops one (the last first), the rest refitted.
void white_time_constants(const DiagnosisProblem& P, const DiagnosisOptions& options, Diagnosis& D,
                          std::set<std::string>& not_held) {
  for (;;) {
    const Eigen::VectorXd& r = D.final_fit.residuals;
    NoiseTreatment t;
    t.sigma_mm = std::sqrt(r.squaredNorm() /
                           std::max(1.0, static_cast<double>(r.size() - D.final_fit.num_free)));
    if (!(t.sigma_mm > 0.0)) return;
    profile_time_constants(P, t, 1.0, D);
    for (Finding& F : D.findings) F.parameters = parameters_of(D.final_fit, F.effect);
    if (!options.hold_by_weight || all_determined_as_reported(options, D)) return;
    drop_last_finding(options, reported_sigmas(D.findings.back()) >= options.min_determined_sigma,
                      "the final fit, its time constants profiled,", D, not_held,
                      earlier_determined_as_reported(options, D));
    EffectModel found;
    found.linear_reference = P.mean_commanded_xyz();
    for (const Finding& F : D.findings) found.effects.push_back(F.effect);
    D.final_fit = P.fit(found);
  }
}

// A white diagnosis' findings against the stream levels the white residuals cannot show: the
// readings' variation within each stream is what the final fit leaves, RSS / (n - free
// parameters); what the declared noise holds beyond it is a level per stream (HiddenLevels),
// e.g. 1/f-like noise whose slow part a stylus_radius_offset took, leaving white residuals of
// 0.30 um where 0.50 um was declared. Nothing changes where the residuals show the declared
// variance.
void white_hidden_levels(const DiagnosisProblem& P, const DiagnosisOptions& options, Diagnosis& D,
                         std::set<std::string>& not_held) {
  if (D.findings.empty()) return;
  if (!P.declared_noise_um()) {
    white_time_constants(P, options, D, not_held);
    return;
  }
  const Eigen::VectorXd& r = D.final_fit.residuals;
  NoiseModelOptions white_streams;
  white_streams.max_order = 0;
  NoiseModel m = estimate_noise_model(P.groups(), P.times(), r, white_streams);
  const double s_um =
      std::sqrt(r.squaredNorm() /
                std::max(1.0, static_cast<double>(r.size() - D.final_fit.num_free))) *
      1e3;
  for (NoiseStream& st : m.streams) st.marginal_sigma_um = st.innovation_sigma_um = s_um;
  NoiseTreatment t;
  t.sigma_mm = s_um * 1e-3;
  t.W = std::make_shared<ArWhitener>(m);
  with_hidden_levels(P, m, t);
  if (t.full)
    refit_findings(P, options, t, D, not_held);
  else
    white_time_constants(P, options, D, not_held);
}

// One pass of the diagnosis: the search, what it leaves, the final numbers. A held member the
// final GLS finds undetermined goes into cache.not_held (refit_findings).
Diagnosis diagnose_pass(const DiagnosisProblem& P, const DiagnosisOptions& options,
                        const std::vector<Effect>& candidates, const ModelFit& baseline,
                        SearchCache& cache) {
  std::set<std::string> not_held;
  // Correlated at all? Judged on the baseline residuals: if even they are white (nothing
  // unmodelled, white noise), every decision is the white-noise one.
  NoiseModel model = estimate_noise_model(P.groups(), P.times(), baseline.residuals, options.noise);
  Diagnosis D;
  if (!options.model_noise || (model.white() && !lacks_declared_variance(P, baseline))) {
    D = search_white(P, options, candidates, baseline, cache);
    white_hidden_levels(P, options, D, not_held);
  } else {
    const NoiseModel searched = model;
    const NoiseTreatment coloured = coloured_treatment(searched),
                         white = white_treatment(P, baseline);
    D = search(P, options, candidates, baseline, coloured, &searched, white, cache);
    // Reported: the noise model of what the final model leaves. If that is white, the
    // correlation was the unmodelled effects': the white-noise diagnosis is the right one.
    model = estimate_noise_model(P.groups(), P.times(), D.final_fit.residuals, options.noise);
    // Judged on the search's picks where the model holds other members (SearchCache::picks):
    // a held radial_motion_A_h2 left AR(4) residuals where the pick radial_motion_A_h3 left
    // white ones, and the coloured search kept named the truth 0.72 where the white one named it
    // alone at 0.97 (bench/diagnosis_confusion.py, AC-trt ballbar, white noise).
    const ModelFit& picked = picks_fit(P, cache, D);
    const bool white_after =
        &picked == &D.final_fit
            ? model.white() && !lacks_declared_variance(P, D.final_fit)
            : estimate_noise_model(P.groups(), P.times(), picked.residuals, options.noise)
                      .white() &&
                  !lacks_declared_variance(P, picked);
    if (white_after) {
      D = Diagnosis{};  // released before the white search builds its own
      D = search_white(P, options, candidates, baseline, cache);
      white_hidden_levels(P, options, D, not_held);
    } else {
      judge_kept(P, options, baseline, coloured, &searched, white, cache, D);
      // The baseline's adequacy against the noise as the final model leaves it (the baseline
      // model of the noise has the unmodelled effects in it).
      const NoiseTreatment final_noise = coloured_treatment(model);
      const double chi2 = final_noise.whiten(baseline.residuals).squaredNorm();
      D.baseline.noise_um = model.sigma_um;
      D.baseline.noise_source = final_noise.source;
      D.baseline.chi2_per_dof = chi2 / D.baseline.dof;
      D.baseline.p_value = stats::chi2_sf(chi2, D.baseline.dof);
      final_gls(P, options, model, D, not_held);  // the final numbers by GLS under that noise
    }
  }
  D.noise = std::move(model);
  cache.not_held.insert(not_held.begin(), not_held.end());
  return D;
}

}  // namespace

Diagnosis diagnose(const DiagnosisProblem& P, const DiagnosisOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Effect> candidates = candidate_list(P, options);
  EffectModel none;
  none.linear_reference = P.mean_commanded_xyz();
  const ModelFit baseline = P.fit(none);
  SearchCache cache;
  Diagnosis D = diagnose_pass(P, options, candidates, baseline, cache);
  // A held member the final GLS left undetermined: the search again, holding the next member of
  // its group by weight (the fits are cached). At most as many passes as findings can be dropped.
  for (int pass = 0; pass < options.max_findings; ++pass) {
    const std::size_t known = cache.not_held.size();
    if (known == 0) break;
    Diagnosis again = diagnose_pass(P, options, candidates, baseline, cache);
    if (cache.not_held.size() == known) {  // nothing new passed over: this pass is the result
      D = std::move(again);
      break;
    }
    D = std::move(again);
  }
  judge_noise_structure(P, options, D);  // structure the noise model took in (final_test.cpp)
  D.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return D;
}

}  // namespace rotacal
