// The diagnosis search loop: baseline fit, candidates scored round by round, the best
// significant one added and the model refitted, then what is left.
#include "rotacal/diagnose/diagnosis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>

#include "rotacal/core/stats.hpp"
#include "scoring.hpp"

namespace rotacal {

using namespace diagnosis_detail;

namespace {

Diagnosis diagnose_at_noise(const DiagnosisProblem& P, const DiagnosisOptions& options,
                            std::optional<double> noise_override, const std::string& noise_source);

}  // namespace

Diagnosis diagnose(const DiagnosisProblem& P, const DiagnosisOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  Diagnosis D = diagnose_at_noise(P, options, std::nullopt, "");
  if (!P.declared_noise_um()) {
    // Successive differences overestimate the noise when the sampling is sparse against the
    // systematic errors (an R-test's 30 degree steps): if the extended model leaves less, that
    // is the better estimate, and the statistics are redone with it.
    const double n = static_cast<double>(D.final_fit.residuals.size());
    const double s_final =
        std::sqrt(D.final_fit.residuals.squaredNorm() / std::max(1.0, n - D.final_fit.num_free)) * 1e3;
    if (s_final < 0.8 * D.baseline.noise_um) {
      std::ostringstream why;
      why.precision(3);
      why << "estimated from the residuals of the extended model (successive differences gave "
          << D.baseline.noise_um << " um: the sampling is too sparse for them)";
      D = diagnose_at_noise(P, options, s_final, why.str());
    }
  }
  D.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return D;
}

namespace {

Diagnosis diagnose_at_noise(const DiagnosisProblem& P, const DiagnosisOptions& options,
                            std::optional<double> noise_override, const std::string& noise_source) {
  Diagnosis D;
  D.machine = P.machine();
  std::vector<Effect> candidates = P.candidates(options.max_harmonic);
  if (!options.only.empty()) {
    std::vector<Effect> keep;
    for (const std::string& id : options.only) {
      const Effect e = Effect::parse(id);
      if (std::find(candidates.begin(), candidates.end(), e) == candidates.end())
        throw InvalidArgument("options.only: " + id + " is not a candidate for this session");
      keep.push_back(e);
    }
    candidates = keep;
  }

  ModelFit fit = P.fit(EffectModel{});
  D.baseline_fit = fit;
  const double n = static_cast<double>(fit.residuals.size());
  const std::optional<double> declared = P.declared_noise_um();
  const double noise_um = declared ? *declared : noise_override ? *noise_override : estimate_noise_um(P, fit.residuals);
  const double sigma_mm = noise_um * 1e-3;
  D.baseline.noise_um = noise_um;
  D.baseline.noise_source = declared         ? "declared"
                            : noise_override ? noise_source
                                             : "estimated from successive differences";
  D.baseline.residual_rms_um = rms_um(fit.residuals);
  D.baseline.n = fit.residuals.size();
  D.baseline.dof = static_cast<int>(n) - fit.num_free;
  const double chi2 = rss(fit.residuals) / (sigma_mm * sigma_mm);
  D.baseline.chi2_per_dof = chi2 / D.baseline.dof;
  D.baseline.p_value = stats::chi2_sf(chi2, D.baseline.dof);
  D.structure_before = residual_structure(P, fit.residuals);

  // A *_hn candidate of an order its axis' sampling cannot resolve takes, at the sampled
  // angles, the values of lower orders (C every 30 deg: order 7 is order 5): scored, it would
  // name an order the data cannot tell. Judged on every reading's angle of that axis, since the
  // effect's parameters are shared by all of them.
  std::vector<std::string> unresolved(candidates.size());
  {
    std::map<char, int> top;
    for (const Effect& c : candidates)
      if (c.harmonic > 0) top[c.axis] = std::max(top[c.axis], c.harmonic);
    for (const auto& [axis, order] : top) {
      std::vector<double> th;
      for (const RotaryAngles<double>& r : P.angles()) th.push_back(axis == 'C' ? r.rot : r.tilt);
      const HarmonicResolution res =
          resolve_harmonics(th, axis, order, options.min_harmonic_new_content);
      for (std::size_t c = 0; c < candidates.size(); ++c)
        if (candidates[c].axis == axis && candidates[c].harmonic > res.resolved)
          unresolved[c] = "the sampling cannot resolve its harmonic order: " +
                          res.why_not(candidates[c].harmonic);
    }
  }

  const std::vector<int> fold = cv_folds(P, options.cv_blocks);
  EffectModel model;
  std::vector<bool> done(candidates.size(), false);
  bool first_round = true;
  for (int step = 0; step < options.max_findings; ++step) {
    const Eigen::MatrixXd Jfree = free_columns(fit.jacobian);
    const Eigen::MatrixXd Q = orthonormal_basis(Jfree);
    std::vector<Score> scores;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      if (done[c]) continue;
      if (!unresolved[c].empty()) {
        D.unobservable.push_back({candidates[c].id(), unresolved[c]});
        done[c] = true;
        continue;
      }
      Score s = score(P, fit, Jfree, Q, candidates[c], sigma_mm, options.min_visible_chi2);
      if (!s.observable) {
        if (first_round) D.unobservable.push_back({candidates[c].id(), s.why_not});
        done[c] = true;
        continue;
      }
      scores.push_back(std::move(s));
    }
    first_round = false;
    std::vector<CandidateScore> table;
    for (const Score& s : scores)
      table.push_back({s.effect.id(), s.k, s.delta_bic, s.f_pvalue, std::sqrt(s.rss1 / n) * 1e3});
    std::sort(table.begin(), table.end(),
              [](const CandidateScore& a, const CandidateScore& b) { return a.delta_bic < b.delta_bic; });
    D.rounds.push_back(std::move(table));
    const double m_tests = std::max<double>(1.0, static_cast<double>(scores.size()));
    std::vector<const Score*> passing;
    for (const Score& s : scores)
      if (s.f_pvalue < options.alpha / m_tests && s.delta_bic < options.min_delta_bic) passing.push_back(&s);
    std::sort(passing.begin(), passing.end(),
              [](const Score* a, const Score* b) { return a->delta_bic < b->delta_bic; });
    const Score* chosen = nullptr;
    double cv_before = 0.0, cv_after = 0.0;
    for (const Score* s : passing) {
      cv_before = cv_rms_um(Jfree, fit.residuals, fold, options.cv_blocks);
      cv_after = cv_rms_um(s->X, fit.residuals, fold, options.cv_blocks);
      if (cv_after < cv_before) {
        chosen = s;
        break;
      }
    }
    if (!chosen) break;

    // Candidates that explain the same signal about as well.
    Ambiguity amb;
    for (const Score* s : passing) {
      if (s == chosen) continue;
      const double dbic = s->delta_bic - chosen->delta_bic;
      const double corr = std::abs(correlation(s->signature, chosen->signature));
      if (dbic < options.ambiguity_delta_bic && corr >= options.ambiguity_correlation) {
        if (amb.effects.empty()) amb.effects.push_back(chosen->effect.id());
        amb.effects.push_back(s->effect.id());
        amb.delta_bic = std::max(amb.delta_bic, dbic);
        amb.correlation = amb.effects.size() == 2 ? corr : std::min(amb.correlation, corr);
        amb.separating_test = separating_test(P, fit, *chosen, *s, sigma_mm);
      }
    }
    if (!amb.effects.empty()) D.ambiguous.push_back(amb);

    // Add it and refit the whole model (nonlinear).
    const Effect effect = chosen->effect;
    for (std::size_t c = 0; c < candidates.size(); ++c)
      if (candidates[c] == effect) done[c] = true;
    model.effects.push_back(effect);
    const double rss_before = rss(fit.residuals);
    const double rms_before = rms_um(fit.residuals);
    const double f_p = chosen->f_pvalue;
    const ModelFit before = fit;
    fit = P.fit(model);
    Finding F;
    F.effect = effect;
    F.cause = effect.cause();
    F.gain.rms_before_um = rms_before;
    F.gain.rms_after_um = rms_um(fit.residuals);
    F.gain.delta_bic = n * std::log(std::max(rss(fit.residuals), 1e-300) / rss_before) +
                       (fit.num_free - before.num_free) * std::log(n);
    F.gain.cv_rms_before_um = cv_before;
    F.gain.cv_rms_after_um = cv_after;
    F.gain.f_pvalue = f_p;
    for (const ParameterEstimate& b : before.parameters) {
      for (const ParameterEstimate& a : fit.parameters) {
        if (a.name != b.name || !a.observable || !b.observable) continue;
        if (std::abs(a.value - b.value) > std::max(a.std, 1e-15))
          F.shifts.push_back({a.name, b.value, a.value, a.std, a.unit});
      }
    }
    D.findings.push_back(F);
  }

  // Effect parameters from the final fit.
  for (Finding& F : D.findings) {
    const std::string id = F.effect.id();
    for (const ParameterEstimate& p : fit.parameters)
      if (p.name == id || p.name.rfind(id + ".", 0) == 0) F.parameters.push_back(p);
  }
  D.final_fit = fit;
  D.structure_after = residual_structure(P, fit.residuals);
  const int dof = static_cast<int>(n) - fit.num_free;
  const double chi2_final = rss(fit.residuals) / (sigma_mm * sigma_mm);
  D.unexplained.chi2_per_dof = chi2_final / dof;
  D.unexplained.p_value = stats::chi2_sf(chi2_final, dof);
  D.unexplained.present = D.unexplained.p_value < 1e-3;
  if (D.unexplained.present) D.unexplained.signature = describe_structure(D.structure_after);
  return D;
}

}  // namespace

}  // namespace rotacal
