// The diagnosis search loop: baseline fit, candidates scored round by round, the best
// significant one added and the model refitted, then what is left.
#include "rotacal/diagnose/diagnosis.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <sstream>

#include "rotacal/ballbar/test_plan.hpp"
#include "rotacal/core/stats.hpp"
#include "rivals.hpp"
#include "scoring.hpp"
#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

using namespace diagnosis_detail;

namespace {

// How the noise enters every decision: white with one sigma, or whitened by an AR model.
struct NoiseTreatment {
  double sigma_mm = 0.0;  // white: the sigma; coloured: the marginal sigma (for wording)
  std::string source;
  std::shared_ptr<const ArWhitener> W;  // null: white
  Eigen::MatrixXd whiten(const Eigen::MatrixXd& M) const {
    if (!W) return M / sigma_mm;
    Eigen::MatrixXd out = M;
    W->apply(out);
    return out;
  }
};

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
std::vector<std::string> unresolved_orders(const DiagnosisProblem& P, const std::vector<Effect>& candidates,
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

// How many sigma from zero the best-determined combination of `effect`'s observable free
// parameters is in `refit`, under noise treatment t: sqrt(v^T C_ee^-1 v), C the refit's
// covariance of its free parameters (the whitened Gram matrix's inverse), e the effect's.
double determined_sigmas(const ModelFit& refit, const Effect& effect, const NoiseTreatment& t) {
  const std::string id = effect.id();
  std::vector<Eigen::Index> free, mine;
  for (Eigen::Index j = 0; j < refit.jacobian.cols(); ++j) {
    if (refit.jacobian.col(j).squaredNorm() == 0.0) continue;
    const ParameterEstimate& p = refit.parameters[static_cast<std::size_t>(j)];
    if ((p.name == id || p.name.rfind(id + ".", 0) == 0) && p.observable) mine.push_back(static_cast<Eigen::Index>(free.size()));
    free.push_back(j);
  }
  if (mine.empty()) return 0.0;
  Eigen::MatrixXd Jf(refit.jacobian.rows(), static_cast<Eigen::Index>(free.size()));
  for (std::size_t a = 0; a < free.size(); ++a) Jf.col(static_cast<Eigen::Index>(a)) = refit.jacobian.col(free[a]);
  const Eigen::MatrixXd Jw = t.whiten(Jf);
  const Eigen::MatrixXd C = (Jw.transpose() * Jw).ldlt().solve(Eigen::MatrixXd::Identity(Jf.cols(), Jf.cols()));
  const Eigen::Index k = static_cast<Eigen::Index>(mine.size());
  Eigen::MatrixXd Cee(k, k);
  Eigen::VectorXd v(k);
  for (Eigen::Index a = 0; a < k; ++a) {
    v[a] = refit.parameters[static_cast<std::size_t>(free[static_cast<std::size_t>(mine[static_cast<std::size_t>(a)])])].value;
    for (Eigen::Index b = 0; b < k; ++b) Cee(a, b) = C(mine[static_cast<std::size_t>(a)], mine[static_cast<std::size_t>(b)]);
  }
  const double chi2 = v.dot(Cee.ldlt().solve(v));
  return std::isfinite(chi2) && chi2 > 0.0 ? std::sqrt(chi2) : 0.0;
}

// Why the first of `aliases` is not resolved (the sampling's words).
std::string unresolved_reason(const std::vector<Effect>& candidates, const std::vector<std::string>& unresolved,
                              const std::vector<Alternative>& aliases) {
  for (std::size_t c = 0; c < candidates.size(); ++c)
    if (!aliases.empty() && candidates[c].id() == aliases.front().effect) return unresolved[c];
  return "";
}

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

NoiseTreatment white_treatment(const DiagnosisProblem& P, const ModelFit& baseline);
// `described`: with the model's summary as the source (the candidates' own models and the
// structure test's are never reported, and formatting a summary per candidate is wasted).
NoiseTreatment coloured_treatment(const NoiseModel& m, bool described = true);

// The noise model of what the current model extended by candidate c (linearised) leaves;
// white treatment if that is white. Its AR order is looked for up to `max_order` (the search's
// noise model's order + 2: the candidate's residual differs from the current model's in the k
// directions it adds, which do not raise the order of the noise's correlation; Burg's recursion
// through all 8 orders for every candidate was most of this function's time).
NoiseTreatment candidate_treatment(const NoiseStreamLayout& layout, const NoiseModelOptions& noise_options,
                                   const ModelFit& fit, const Eigen::MatrixXd& Q_raw, const Eigen::VectorXd& Qr,
                                   const Eigen::MatrixXd& Jc, const NoiseTreatment& white, NoiseModel* model) {
  Eigen::VectorXd r = residual_without(Q_raw, fit.residuals, Qr, Jc);
  if (r.size() == 0) {
    // What the candidate adds to the model's span, orthonormalised (CholeskyQR2; the
    // rank-revealing QR where it is near rank-deficient): r minus its projection on that.
    const Eigen::MatrixXd B = orthonormal_basis_full_rank(project_out(Q_raw, Jc));
    r = fit.residuals - B * (B.transpose() * fit.residuals);
  }
  *model = estimate_noise_model(layout, r, noise_options);
  return model->white() ? white : coloured_treatment(*model, false);
}

// What the searches of one diagnosis share: a diagnosis may search twice (with the noise
// model, then white when the final model leaves white residuals) through the same models, and
// a model's refit and its candidates' Jacobians depend on the model alone. Jacobians are kept
// up to kMaxCachedValues doubles (16 MB), beyond that recomputed; a cached Jacobian and the
// batch that handed it out share one matrix (a copy of each doubled the diagnosis' peak memory
// on a 1 kHz recording: bench/ballbar_long --diagnose).
using SharedMatrix = std::shared_ptr<const Eigen::MatrixXd>;
struct SearchCache {
  static constexpr std::size_t kMaxCachedValues = std::size_t{2} << 20;
  std::map<std::string, ModelFit> fits;
  std::map<std::string, std::map<std::string, SharedMatrix>> jacobians;
  std::size_t cached_values = 0;

  static std::string key(const EffectModel& m) {
    std::string k;
    for (const Effect& e : m.effects) k += e.id() + ";";
    return k;
  }
  const ModelFit& fit(const DiagnosisProblem& P, const EffectModel& m) {
    const std::string k = key(m);
    auto it = fits.find(k);
    if (it == fits.end()) it = fits.emplace(k, P.fit(m)).first;
    return it->second;
  }
  // The Jacobians of `todo` at `at` (the fit of model `m`).
  std::vector<SharedMatrix> candidate_jacobians(const DiagnosisProblem& P, const EffectModel& m,
                                                const ModelFit& at, const std::vector<Effect>& todo) {
    std::map<std::string, SharedMatrix>& known = jacobians[key(m)];
    std::vector<Effect> missing;
    for (const Effect& c : todo)
      if (!known.count(c.id())) missing.push_back(c);
    std::vector<Eigen::MatrixXd> fresh = P.candidate_jacobians(at, missing);
    std::vector<SharedMatrix> out;
    for (const Effect& c : todo) {
      const auto it = known.find(c.id());
      if (it != known.end()) {
        out.push_back(it->second);
        continue;
      }
      const std::size_t i = static_cast<std::size_t>(
          std::find(missing.begin(), missing.end(), c) - missing.begin());
      const std::size_t values = static_cast<std::size_t>(fresh[i].size());
      out.push_back(std::make_shared<const Eigen::MatrixXd>(std::move(fresh[i])));
      if (cached_values + values <= kMaxCachedValues) {
        cached_values += values;
        known.emplace(c.id(), out.back());
      }
    }
    return out;
  }
};

// The search: score every candidate against the current model, add the best one that passes
// the F-test (Bonferroni), BIC and blocked cross-validation and whose parameters the refit can
// determine, refit, repeat; then judge what is left.
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
  const std::vector<int> fold = cv_folds(P, options.cv_blocks, noise.W ? model : nullptr);
  EffectModel effects;
  effects.linear_reference = P.mean_commanded_xyz();
  std::vector<bool> done(candidates.size(), false);
  bool first_round = true;
  while (static_cast<int>(D.findings.size()) < options.max_findings) {
    ScoringInputs in;
    in.Jfree = free_columns(fit->jacobian);
    in.Q_w = orthonormal_basis(noise.whiten(in.Jfree));
    in.r_w = noise.whiten(fit->residuals);
    in.num_free = fit->num_free;
    // Coloured: the free columns with one level column per stream appended, for candidates
    // whose own noise model is 1/f-like (see below).
    // Built when a candidate first needs them (n x (p + streams) each: AR(1) noise never does).
    Eigen::MatrixXd Q_raw, J_levels;
    int levels_rank = 0;
    Eigen::VectorXd Qr;  // Q_raw^T r (zero but for the fit's convergence)
    NoiseModelOptions own_noise = options.noise;  // each candidate's own noise model (see candidate_treatment)
    if (noise.W) {
      Q_raw = orthonormal_basis(in.Jfree);
      Qr = Q_raw.transpose() * fit->residuals;
      if (model) own_noise.max_order = std::min(own_noise.max_order, model->max_order + 2);
    }
    const auto need_levels = [&] {
      if (J_levels.size()) return;
      const Eigen::MatrixXd L = stream_levels(P);
      J_levels.resize(in.Jfree.rows(), in.Jfree.cols() + L.cols());
      J_levels << in.Jfree, L;
      levels_rank = static_cast<int>(orthonormal_basis(J_levels).cols() - Q_raw.cols());
    };
    // This round's candidate Jacobians at the current fit, in batches of at most
    // kChunkValues doubles: one batch for a session of a few thousand readings, and a long
    // session holds one batch at a time (the cache keeps what fits its limit).
    constexpr std::size_t kChunkValues = std::size_t{2} << 20;  // 16 MB
    const std::size_t rows = static_cast<std::size_t>(fit->residuals.size());
    std::vector<SharedMatrix> chunk_jc;
    std::vector<std::size_t> chunk_of(candidates.size(), SIZE_MAX);  // index in chunk_jc
    const auto jacobian_of = [&](std::size_t c) -> const Eigen::MatrixXd& {
      if (chunk_of[c] == SIZE_MAX) {
        std::vector<Effect> todo;
        std::size_t values = 0;
        for (std::size_t d = c; d < candidates.size(); ++d) {
          if (done[d] || !unresolved[d].empty()) continue;
          const std::size_t v = rows * static_cast<std::size_t>(candidates[d].num_params());
          if (!todo.empty() && values + v > kChunkValues) break;
          chunk_of[d] = todo.size();
          todo.push_back(candidates[d]);
          values += v;
        }
        chunk_jc.clear();  // the previous batch goes before the next is made
        chunk_jc = cache.candidate_jacobians(P, effects, *fit, todo);
      }
      return *chunk_jc[chunk_of[c]];
    };
    int round_total = 0, round_done = 0;  // candidates to score in this round (progress)
    for (std::size_t c = 0; c < candidates.size(); ++c) round_total += !done[c] && unresolved[c].empty();
    const std::string stage = std::string(noise.W ? "search with the noise model" : "search (white noise)") +
                              ", round " + std::to_string(D.rounds.size() + 1);
    std::vector<Score> scores;
    NoiseTreatment wander_noise;  // 1/f-like: AR(1) + random walk by REML, once per round
    std::unique_ptr<ModelProducts> round_products;  // white or AR(1) candidates' Gram matrices
    std::vector<NoiseTreatment> treatment_of;  // per score: the noise it was judged with
    std::vector<bool> levels_of;               // per score: judged with the stream levels
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      if (done[c]) continue;
      if (!unresolved[c].empty()) {
        D.unobservable.push_back({candidates[c].id(), unresolved[c]});
        done[c] = true;
        continue;
      }
      const Eigen::MatrixXd& Jc = jacobian_of(c);
      if (!Jc.allFinite()) {  // e.g. a time constant over readings that share one time stamp
        if (first_round) D.unobservable.push_back({candidates[c].id(), kUndefinedOnReadings});
        done[c] = true;
        continue;
      }
      if (options.progress) options.progress(stage, round_done++, round_total);
      Score s;
      NoiseTreatment judged_with = noise;
      bool with_levels = false;
      if (!noise.W) {
        s = score(in, candidates[c], noise.whiten(Jc), options.min_visible_chi2, options.min_delta_bic);
      } else {
        // As the classical F-test takes sigma from the larger model, the noise is modelled on
        // what the model extended by this candidate leaves: correlated noise that no candidate
        // follows stays correlated (so it is not taken for an effect), and an effect's own
        // signature is not mistaken for correlated noise (which would whiten it away).
        NoiseModel own_model;
        NoiseTreatment own = candidate_treatment(layout, own_noise, *fit, Q_raw, Qr, Jc, white, &own_model);
        if (own_model.max_order < 2 && (!own.W || own.W->ar1_only())) {
          // White or AR(1): scored from inner products; only a candidate that may pass is
          // scored again below with its columns (the margin of 1 is far beyond rounding).
          if (!round_products)
            round_products = std::make_unique<ModelProducts>(in.Jfree, layout.rows);
          const CandidateProducts g =
              candidate_products(own.W.get(), own.sigma_mm, *round_products, in.Jfree, Jc, fit->residuals);
          std::optional<Score> quick =
              score_from_products(g, candidates[c], fit->num_free, options.min_visible_chi2);
          if (quick && !(quick->observable && quick->delta_bic < options.min_delta_bic + 1.0)) {
            s = std::move(*quick);
            s.rss1 *= in.r_w.squaredNorm() / std::max(g.rr, 1e-300);
            judged_with = own;
            if (!s.observable) {
              if (first_round) D.unobservable.push_back({candidates[c].id(), s.why_not});
              done[c] = true;
              continue;
            }
            scores.push_back(std::move(s));
            treatment_of.push_back(judged_with);
            levels_of.push_back(false);
            continue;
          }
        }
        ScoringInputs in_c;
        in_c.Jfree = in.Jfree;
        in_c.num_free = fit->num_free;
        if (own_model.max_order >= 2) {
          // Noise that AR(1) does not describe (BIC wants p >= 2) is taken as 1/f-like: it has
          // no finite correlation time, and its lowest frequencies are indistinguishable from
          // an offset per stream that no AR model of a few hundred readings captures, so the
          // level of each stream becomes a nuisance parameter. Its slow wander within a test
          // is modelled as a random walk: AR(1) + walk by REML over what the current model and
          // the levels leave (core/noise_handling.hpp), once per round. Burg's AR(p) of a
          // stream of a few hundred readings misses that wander and took it for drifts (23
          // false findings in 200 1/f-like null sessions; with the walk: bench/
          // diagnose_realistic_bench --rho -1).
          need_levels();
          with_levels = true;
          in_c.Jfree = J_levels;
          in_c.num_free += levels_rank;
          if (!wander_noise.W) {
            const NoiseModel start = estimate_noise_model(layout, fit->residuals, options.noise);
            wander_noise = coloured_treatment(estimate_noise_model_reml(start, fit->residuals, J_levels));
          }
          own = wander_noise;
        }
        in_c.Q_w = orthonormal_basis_full_rank(own.whiten(in_c.Jfree));
        in_c.r_w = own.whiten(fit->residuals);
        s = score(in_c, candidates[c], own.whiten(Jc), options.min_visible_chi2, options.min_delta_bic);
        // Scores are kept relative to the whitened residual of the current model, so the
        // table's RMS-after stays comparable.
        s.rss1 *= in.r_w.squaredNorm() / std::max(in_c.r_w.squaredNorm(), 1e-300);
        judged_with = own;
      }
      if (!s.observable) {
        if (first_round) D.unobservable.push_back({candidates[c].id(), s.why_not});
        done[c] = true;
        continue;
      }
      // The columns (cross-validation) and signature (ambiguity) serve only a candidate that
      // can pass: the others' would hold n x (p + k + 1) doubles each, 8 KB per reading over
      // the catalogue, which a 1 kHz recording of a whole test cannot afford.
      if (s.delta_bic < options.min_delta_bic) {
        // Cross-validation compares with the model itself (without any level columns).
        s.X.resize(in.Jfree.rows(), in.Jfree.cols() + s.k);
        s.X << in.Jfree, Jc * s.directions;
      }
      scores.push_back(std::move(s));
      treatment_of.push_back(judged_with);
      levels_of.push_back(with_levels);
    }
    if (options.progress) options.progress(stage, round_total, round_total);
    first_round = false;
    std::vector<CandidateScore> table;
    for (const Score& s : scores) {
      // RMS after, in um: the whitened fraction applied to the raw RMS.
      const double frac = std::sqrt(s.rss1 / std::max(in.r_w.squaredNorm(), 1e-300));
      table.push_back({s.effect.id(), s.k, s.delta_bic, s.f_pvalue, rms_um(fit->residuals) * frac});
    }
    std::sort(table.begin(), table.end(),
              [](const CandidateScore& a, const CandidateScore& b) { return a.delta_bic < b.delta_bic; });
    D.rounds.push_back(std::move(table));
    const double m_tests = std::max<double>(1.0, static_cast<double>(scores.size()));
    std::vector<const Score*> passing;
    for (const Score& s : scores)
      if (s.f_pvalue < options.alpha / m_tests && s.delta_bic < options.min_delta_bic) passing.push_back(&s);
    std::sort(passing.begin(), passing.end(),
              [](const Score* a, const Score* b) { return a->delta_bic < b->delta_bic; });

    // The first passing candidate that also predicts left-out blocks better and whose
    // parameters the nonlinear refit can determine.
    const Score* chosen = nullptr;
    const ModelFit* before = nullptr;  // the current model's fit, once a candidate is chosen
    double cv_before = 0.0, cv_after = 0.0;
    for (const Score* s : passing) {
      cv_before = cv_rms_um(in.Jfree, fit->residuals, fold, options.cv_blocks);
      cv_after = cv_rms_um(s->X, fit->residuals, fold, options.cv_blocks);
      if (!(cv_after < cv_before)) continue;
      EffectModel extended = effects;
      extended.effects.push_back(s->effect);
      const ModelFit& refit = cache.fit(P, extended);
      // A cause with no number is no finding: at least one combination of its parameters must
      // be determined, min_determined_sigma from zero in the refit (a polynomial's correlated
      // coefficients can be so jointly while none is alone), not merely estimable.
      const bool any_determined =
          determined_sigmas(refit, s->effect, treatment_of[static_cast<std::size_t>(s - scores.data())]) >=
          options.min_determined_sigma;
      for (std::size_t c = 0; c < candidates.size(); ++c)
        if (candidates[c] == s->effect) done[c] = true;
      if (!any_determined) {
        D.unobservable.push_back(
            {s->effect.id(), "it reduces the residual, but once it is in the model none of its "
                             "parameters can be determined from these readings (none reaches " +
                                 std::to_string(static_cast<int>(options.min_determined_sigma)) +
                                 " sigma: they trade off against the location errors and the other effects)"});
        continue;
      }
      chosen = s;
      effects = extended;
      before = fit;
      fit = &refit;
      break;
    }
    if (!chosen) break;

    // How sure the name is: posterior weights against the candidates that explain the same
    // signal (rivals.hpp). Below min_weight the finding is the group the data cannot separate,
    // reported ambiguous. The field is every observable candidate of the round that could hold
    // any weight, passed or not (the one that failed the F-test or BIC by a little may still fit
    // as well as the chosen one). It is weighed under one noise model, in coloured noise the
    // chosen candidate's own (each candidate's own model is estimated after removing it: a
    // flexible one that takes some of the noise's low frequencies with it whitens its own
    // residual more, and its BIC flatters it against a rival judged under another model).
    const std::size_t ci = static_cast<std::size_t>(chosen - scores.data());
    const double tempering = noise.W && model ? evidence_tempering(*model) : 1.0;
    const NoiseTreatment& common = noise.W ? treatment_of[ci] : noise;
    ScoringInputs in_common;
    if (noise.W) {
      in_common.Jfree = levels_of[ci] ? J_levels : in.Jfree;
      in_common.num_free = before->num_free + (levels_of[ci] ? levels_rank : 0);
      in_common.Q_w = orthonormal_basis_full_rank(common.whiten(in_common.Jfree));
      in_common.r_w = common.whiten(before->residuals);
    }
    const ScoringInputs& judged_in = noise.W ? in_common : in;
    std::vector<Effect> near;  // within kFieldMargin of the chosen one at either Occam term
    constexpr double kFieldMargin = 40.0;  // a weight of e^-20 at most, before tempering
    for (const Score& s : scores) {
      const double d_bic = s.delta_bic - chosen->delta_bic;
      const double d_aic = d_bic - (s.k - chosen->k) * (std::log(n) - 2.0);
      if (&s == chosen || std::min(d_bic, d_aic) < kFieldMargin) near.push_back(s.effect);
    }
    EffectModel before_effects = effects;
    before_effects.effects.pop_back();
    const std::vector<SharedMatrix> near_jc = cache.candidate_jacobians(P, before_effects, *before, near);
    std::vector<Score> field_scores;
    field_scores.reserve(near.size());
    for (std::size_t i = 0; i < near.size(); ++i)
      field_scores.push_back(score(judged_in, near[i], common.whiten(*near_jc[i]), options.min_visible_chi2));
    std::vector<const Score*> field;
    std::vector<double> field_bic;
    const Score* chosen_judged = chosen;
    for (const Score& s : field_scores) {
      field.push_back(&s);
      field_bic.push_back(s.observable ? s.delta_bic : std::numeric_limits<double>::infinity());
      if (s.effect == chosen->effect && s.observable) chosen_judged = &s;
    }
    const RivalJudgement judged_rivals = weigh_rivals(*chosen_judged, field, field_bic, n, tempering,
                                                      options.rival_correlation, options.min_weight);
    // A harmonic of an order the sampling cannot resolve takes, at the sampled angles, the
    // values of lower orders: a finding of a harmonic of that axis may be it, of its own kind or
    // another (on the R-test's 7 tilt angles an axial h4 came out as a tilt h3).
    std::vector<Alternative> aliases;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const Effect& e = candidates[c];
      if (chosen->effect.harmonic > 0 && e.harmonic > 0 && e.axis == chosen->effect.axis && !unresolved[c].empty()) {
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
              ? separating_test(P, *before, *chosen, *judged_rivals.group[1], noise.sigma_mm)
              : "a finer step of axis " + std::string(1, chosen->effect.axis) +
                    " resolves the higher orders (" + unresolved_reason(candidates, unresolved, aliases) + ")";
      D.ambiguous.push_back(amb);
    }

    Finding F;
    F.effect = chosen->effect;
    F.cause = chosen->effect.cause();
    F.weight = judged_rivals.weight;
    F.rivals = judged_rivals.rivals;
    F.rivals.insert(F.rivals.end(), aliases.begin(), aliases.end());
    F.gain.rms_before_um = rms_um(before->residuals);
    F.gain.rms_after_um = rms_um(fit->residuals);
    const NoiseTreatment& judged = treatment_of[static_cast<std::size_t>(chosen - scores.data())];
    const double rss_before = judged.whiten(before->residuals).squaredNorm();
    const double rss_after = std::max(judged.whiten(fit->residuals).squaredNorm(), 1e-300);
    F.gain.delta_bic = n * std::log(rss_after / rss_before) + (fit->num_free - before->num_free) * std::log(n);
    F.gain.cv_rms_before_um = cv_before;
    F.gain.cv_rms_after_um = cv_after;
    F.gain.f_pvalue = chosen->f_pvalue;
    for (const ParameterEstimate& b : before->parameters) {
      for (const ParameterEstimate& a : fit->parameters) {
        if (a.name != b.name || !a.observable || !b.observable) continue;
        if (std::abs(a.value - b.value) > std::max(a.std, 1e-15))
          F.shifts.push_back({a.name, b.value, a.value, a.std, a.unit});
      }
    }
    D.findings.push_back(F);
  }

  for (Finding& F : D.findings) F.parameters = parameters_of(*fit, F.effect);
  const ModelFit& final_fit = *fit;  // copied into the result last, after the structure test's peak
  D.structure_after = residual_structure(P, final_fit.residuals);
  const int dof = static_cast<int>(n) - final_fit.num_free;
  const Eigen::VectorXd r_w = noise.whiten(final_fit.residuals);
  const double chi2_final = r_w.squaredNorm();
  D.unexplained.chi2_per_dof = chi2_final / dof;
  if (!noise.W) {
    D.unexplained.p_value = stats::chi2_sf(chi2_final, dof);
    const GroupResidual* worst = nullptr;
    for (const GroupResidual& g : D.structure_after)
      if (!worst || g.rms_um > worst->rms_um) worst = &g;
    if (worst) D.unexplained.group = worst->group;
  } else {
    // The noise of the group under test is modelled on the other groups (one AR model pooled
    // over them: the same sensor at the same rate): modelled on the group itself, the AR
    // model would take its structure for correlated noise and whiten it away, and with the
    // tested structure fitted first it would lose the noise's low frequencies with it and find
    // structure in every null session.
    const NoiseModel final_model = estimate_noise_model(layout, final_fit.residuals, options.noise);
    Eigen::MatrixXd Jfree = free_columns(final_fit.jacobian);
    int num_free = final_fit.num_free;
    // 1/f-like: stream levels are nuisance and the noise is AR(1) + a random walk by REML, as
    // in scoring; the Burg AR(p) of each group missed the wander and took it for structure
    // (31 of 200 1/f-like null sessions flagged). Pooled over every stream (three parameters),
    // one group's structure barely moves it.
    NoiseTreatment wander;
    if (final_model.max_order >= 2) {
      const Eigen::MatrixXd L = stream_levels(P);
      Eigen::MatrixXd X(Jfree.rows(), Jfree.cols() + L.cols());
      X << Jfree, L;
      num_free += static_cast<int>(orthonormal_basis(X).cols() - orthonormal_basis(Jfree).cols());
      Jfree = X;
      wander = coloured_treatment(estimate_noise_model_reml(final_model, final_fit.residuals, Jfree));
    }
    NoiseModelOptions pooled = options.noise;
    pooled.pooled = true;
    pooled.pool_only_if_all_coloured = false;
    const NoiseModel pooled_all = estimate_noise_model(layout, final_fit.residuals, pooled);  // its streams
    // The other groups' pooled model, one per group tested: the same residual without one
    // group, its order searched up to the pooled order of all groups + 2 (as for the candidates).
    NoiseModelOptions others_options = pooled;
    others_options.max_order = std::min(pooled.max_order, pooled_all.max_order + 2);
    const auto whitener_for = [&](const std::string& group, const Eigen::MatrixXd&) {
      if (wander.W) return Whiten([wander](const Eigen::MatrixXd& M) { return wander.whiten(M); });
      NoiseTreatment t_noise = white;
      const NoiseStreamLayout others_layout = layout.except_group(group);
      if (!others_layout.rows.empty()) {
        const NoiseModel others = estimate_noise_model(others_layout, final_fit.residuals, others_options);
        if (!others.white()) {
          NoiseModel all = pooled_all;
          const NoiseStream& o = others.streams.front();
          for (NoiseStream& st : all.streams) {
            st.reflection = o.reflection, st.ar = o.ar;
            st.marginal_sigma_um = o.marginal_sigma_um, st.innovation_sigma_um = o.innovation_sigma_um;
          }
          t_noise = coloured_treatment(all, false);
        }
      }
      return Whiten([t_noise](const Eigen::MatrixXd& M) { return t_noise.whiten(M); });
    };
    const StructureTest T = structure_test(P, final_fit.residuals, Jfree, num_free, whitener_for);
    D.unexplained.p_value = T.p_value;
    D.unexplained.group = T.group;
  }
  D.unexplained.present = D.unexplained.p_value < 1e-3;
  if (D.unexplained.present) {
    D.unexplained.signature = describe_structure(D.structure_after);
    if (!D.unexplained.group.empty()) {
      const Location L = locate(P, final_fit.residuals, D.unexplained.group);
      D.unexplained.axis = L.axis;
      D.unexplained.range_from = L.from;
      D.unexplained.range_to = L.to;
      std::ostringstream where;
      where.precision(4);
      where << "; in '" << D.unexplained.group << "' the residual is largest at "
            << (L.axis ? std::string(1, L.axis) + " " : std::string("t ")) << L.from << ".." << L.to
            << (L.axis ? " deg" : " s") << " (" << L.peak_um << " um mean there)";
      D.unexplained.signature += where.str();
      // A function of one rotary angle: offer the per-angle table as the extension.
      if (L.axis) {
        const NoiseModel left = estimate_noise_model(layout, final_fit.residuals, options.noise);
        AngleTable T = angle_table(P, final_fit.residuals, D.unexplained.group, left, noise.sigma_mm * 1e3,
                                   options.cv_blocks);
        if (T.gain.cv_rms_after_um < T.gain.cv_rms_before_um) D.angle_tables.push_back(std::move(T));
      }
    }
  }
  D.final_fit = final_fit;
  return D;
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

// White treatment, redone once with the extended model's residual when successive
// differences overestimated the noise (sparse sampling against the systematic errors, as an
// R-test's 30 degree steps): if the extended model leaves less, that is the better estimate.
Diagnosis search_white(const DiagnosisProblem& P, const DiagnosisOptions& options,
                       const std::vector<Effect>& candidates, const ModelFit& baseline, SearchCache& cache) {
  const NoiseTreatment white = white_treatment(P, baseline);
  Diagnosis D = search(P, options, candidates, baseline, white, nullptr, white, cache);
  if (!P.declared_noise_um()) {
    const double n = static_cast<double>(D.final_fit.residuals.size());
    const double s_final =
        std::sqrt(D.final_fit.residuals.squaredNorm() / std::max(1.0, n - D.final_fit.num_free)) * 1e3;
    if (s_final < 0.8 * D.baseline.noise_um) {
      NoiseTreatment better;
      better.sigma_mm = s_final * 1e-3;
      std::ostringstream why;
      why.precision(3);
      why << "estimated from the residuals of the extended model (successive differences gave "
          << D.baseline.noise_um << " um: the sampling is too sparse for them)";
      better.source = why.str();
      D = search(P, options, candidates, baseline, better, nullptr, better, cache);
    }
  }
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
  // Correlated at all? Judged on the baseline residuals: if even they are white (nothing
  // unmodelled, white noise), every decision is the white-noise one.
  NoiseModel model = estimate_noise_model(P.groups(), P.times(), baseline.residuals, options.noise);
  Diagnosis D;
  if (!options.model_noise || model.white()) {
    D = search_white(P, options, candidates, baseline, cache);
  } else {
    D = search(P, options, candidates, baseline, coloured_treatment(model), &model, white_treatment(P, baseline),
               cache);
    // Reported: the noise model of what the final model leaves. If that is white, the
    // correlation was the unmodelled effects': the white-noise diagnosis is the right one.
    model = estimate_noise_model(P.groups(), P.times(), D.final_fit.residuals, options.noise);
    if (model.white()) {
      D = Diagnosis{};  // released before the white search builds its own
      D = search_white(P, options, candidates, baseline, cache);
    } else {
      // The baseline's adequacy against the noise as the final model leaves it (the baseline
      // model of the noise has the unmodelled effects in it).
      const NoiseTreatment final_noise = coloured_treatment(model);
      const double chi2 = final_noise.whiten(baseline.residuals).squaredNorm();
      D.baseline.noise_um = model.sigma_um;
      D.baseline.noise_source = final_noise.source;
      D.baseline.chi2_per_dof = chi2 / D.baseline.dof;
      D.baseline.p_value = stats::chi2_sf(chi2, D.baseline.dof);
      // The numbers of the final model by GLS under that noise: the white fit's covariance of
      // AR(1) 0.9 readings is some 4x too small (2-sigma coverage of the ballbar's findings 32 %,
      // bench/diagnosis_confusion.py). The noise for it by REML over what the fit leaves (Burg on
      // the residuals misses the slow noise the fitted directions took: 84 % with it, 89 % by
      // REML), and the covariance scaled by the whitened chi-square per dof where that exceeds 1.
      if (!D.findings.empty()) {
        EffectModel found;
        found.linear_reference = P.mean_commanded_xyz();
        for (const Finding& F : D.findings) found.effects.push_back(F.effect);
        const NoiseTreatment gls_noise = coloured_treatment(
            estimate_noise_model_reml(model, D.final_fit.residuals, free_columns(D.final_fit.jacobian)), false);
        D.final_fit = P.fit_gls(found, gls_noise.W);
        const double chi2_per_dof = gls_noise.whiten(D.final_fit.residuals).squaredNorm() /
                                    std::max(1.0, static_cast<double>(D.final_fit.residuals.size() - D.final_fit.num_free));
        for (Finding& F : D.findings) {
          F.parameters = parameters_of(D.final_fit, F.effect);
          for (ParameterEstimate& q : F.parameters) q.std *= std::sqrt(std::max(1.0, chi2_per_dof));
        }
      }
    }
  }
  D.noise = std::move(model);
  D.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return D;
}

}  // namespace rotacal
