// SPDX-License-Identifier: BSD-3-Clause
// One round of the diagnosis search: every candidate not yet done scored against the current
// model by a linearised refit (scoring.hpp), in white noise with the search's sigma, in coloured
// noise under each candidate's own noise model.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>

#include "search.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// The noise model of what the current model extended by candidate c (linearised) leaves;
// white treatment if that is white. Its AR order is looked for up to `max_order` (the search's
// noise model's order + 2: the candidate's residual differs from the current model's in the k
// directions it adds, which do not raise the order of the noise's correlation; Burg's recursion
// through all 8 orders for every candidate was most of this function's time).
NoiseTreatment candidate_treatment(const NoiseStreamLayout& layout,
                                   const NoiseModelOptions& noise_options, const ModelFit& fit,
                                   const Eigen::MatrixXd& Q_raw, const Eigen::VectorXd& Qr,
                                   const Eigen::MatrixXd& Jc, const NoiseTreatment& white,
                                   NoiseModel* model) {
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

// What a coloured round shares between its candidates: the free columns' basis, the level
// columns (built when a 1/f-like candidate first needs them), the white or AR(1) candidates'
// Gram matrices, the 1/f-like noise model (once per round).
struct ColouredRound {
  Eigen::MatrixXd Q_raw;        // orthonormal basis of the free columns
  Eigen::VectorXd Qr;           // Q_raw^T r (zero but for the fit's convergence)
  NoiseModelOptions own_noise;  // each candidate's own noise model (see candidate_treatment)
  std::string model_key;        // SearchCache::key of the current model
  NoiseModel wander_start;      // 1/f-like: the current residuals' AR model, REML's start
  NoiseTreatment wander_noise;  // 1/f-like: AR(1) + random walk by REML, once per round
  std::unique_ptr<ModelProducts> products;  // white or AR(1) candidates' Gram matrices
  // The current model under wander_noise, without and with the level columns: the same for
  // every candidate judged under the round's walk (a basis of n x (p + levels) whitened
  // columns each, most of a 1/f-like round's scoring when made per candidate).
  std::optional<ScoringInputs> wander_in[2];
  bool slow = false;  // the round's noise is 1/f-like for every candidate (lacks_declared_variance)
};

// The 1/f-like treatment (AR(1) + walk by REML, bounded by the declared noise, with the hidden
// stream levels) estimated with candidate c's columns in the model beside the levels, so that
// its own signature is not taken for the walk.
NoiseTreatment walk_with_candidate(const SearchContext& S, const ModelFit& fit, const Round& R,
                                   const ColouredRound& C, const Eigen::MatrixXd& Jc) {
  Eigen::MatrixXd X(R.J_levels.rows(), R.J_levels.cols() + Jc.cols());
  X << R.J_levels, Jc;
  NoiseModel walk = estimate_noise_model_reml(C.wander_start, fit.residuals, X);
  with_walk_bounded_by_declared(S.P, fit.residuals, walk);
  NoiseTreatment own = coloured_treatment(walk);
  with_hidden_levels(S.P, walk, own);
  return own;
}

// The share of candidate signature Jc, beyond the model's span (orthonormal Q_raw), that is a level
// and a slope per noise stream (slope over the reading's index in the stream): what the 1/f-like
// treatment's levels and walk take most of. Ballbar thermal drifts and warm-ups 0.20-0.51, the
// length offset 0.78; harmonics, straightness and squareness 0.02-0.23 (BC-trt, AC-trt, seed 223).
double slow_share(const NoiseStreamLayout& layout, const Eigen::MatrixXd& Q_raw,
                  const Eigen::MatrixXd& Jc) {
  const Eigen::MatrixXd Jp = project_out(Q_raw, Jc);
  const double all = Jp.squaredNorm();
  if (!(all > 0.0)) return 0.0;
  double slow = 0.0;
  for (const std::vector<Eigen::Index>& rows : layout.rows) {
    const double n = static_cast<double>(rows.size());
    if (rows.size() < 2) continue;
    Eigen::RowVectorXd level = Eigen::RowVectorXd::Zero(Jp.cols()), slope = level;
    double t2 = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double t = static_cast<double>(i) - (n - 1.0) / 2.0;
      level += Jp.row(rows[i]);
      slope += t * Jp.row(rows[i]);
      t2 += t * t;
    }
    slow += level.squaredNorm() / n + slope.squaredNorm() / t2;
  }
  return slow / all;
}

// The current model under the noise treatment t, with the stream levels as nuisance
// parameters if `with_levels`: what score_under scores a candidate against.
ScoringInputs inputs_under(const ModelFit& fit, const Round& R, const NoiseTreatment& t,
                           bool with_levels) {
  ScoringInputs in_c;
  in_c.Jfree = with_levels ? R.J_levels : R.in.Jfree;
  in_c.num_free = fit.num_free + (with_levels ? R.levels_rank : 0);
  in_c.Q_w = orthonormal_basis_full_rank(t.whiten(in_c.Jfree));
  in_c.r_w = t.whiten(fit.residuals);
  return in_c;
}

// Candidate c scored under the noise treatment t against in_c (inputs_under, of t).
Score score_under(const SearchContext& S, const Round& R, const ScoringInputs& in_c,
                  const Effect& c, const Eigen::MatrixXd& Jc, const NoiseTreatment& t) {
  Score s = score(in_c, c, t.whiten(Jc), S.options.min_visible_chi2, S.options.min_delta_bic);
  // Scores are kept relative to the whitened residual of the current model, so the
  // table's RMS-after stays comparable.
  s.rss1 *= R.in.r_w.squaredNorm() / std::max(in_c.r_w.squaredNorm(), 1e-300);
  return s;
}

// Candidate c scored in coloured noise. Returns false where it is not observable (s.why_not
// says why); else `s`, the noise it was judged with and whether with the stream levels, and
// in `round_walk` whether under the round's 1/f-like treatment (estimated without c's columns).
void score_coloured(const SearchContext& S, const ModelFit& fit, Round& R, ColouredRound& C,
                    const Effect& c, const Eigen::MatrixXd& Jc, Score& s,
                    NoiseTreatment& judged_with, bool& with_levels, bool& round_walk) {
  const DiagnosisOptions& options = S.options;
  // As the classical F-test takes sigma from the larger model, the noise is modelled on
  // what the model extended by this candidate leaves: correlated noise that no candidate
  // follows stays correlated (so it is not taken for an effect), and an effect's own
  // signature is not mistaken for correlated noise (which would whiten it away).
  NoiseModel own_model;
  NoiseTreatment own =
      candidate_treatment(S.layout, C.own_noise, fit, C.Q_raw, C.Qr, Jc, S.white, &own_model);
  if (!C.slow && own_model.max_order < 2 && (!own.W || own.W->ar1_only())) {
    // White or AR(1): scored from inner products; only a candidate that may pass is
    // scored again below with its columns (the margin of 1 is far beyond rounding).
    if (!C.products) C.products = std::make_unique<ModelProducts>(R.in.Jfree, S.layout.rows);
    const CandidateProducts g =
        candidate_products(own.W.get(), own.sigma_mm, *C.products, R.in.Jfree, Jc, fit.residuals);
    std::optional<Score> quick = score_from_products(g, c, fit.num_free, options.min_visible_chi2);
    if (quick && !(quick->observable && quick->delta_bic < options.min_delta_bic + 1.0)) {
      s = std::move(*quick);
      s.rss1 *= R.in.r_w.squaredNorm() / std::max(g.rr, 1e-300);
      judged_with = own;
      return;
    }
  }
  if (C.slow || own_model.max_order >= 2) {
    // Noise that AR(1) does not describe (BIC wants p >= 2), or whose declared variance the
    // current residuals lack (C.slow, the same for every candidate of the round: a candidate
    // that follows the slow wander leaves a residual that looks white or AR(1) itself, and was
    // then judged under that, taking the wander for an effect; 7 of 200 1/f-like probe null
    // sessions named straightness_ZY, axial_motion_C_h2, A harmonics or Z drifts, 0 with it,
    // bench/diagnosis_confusion.py --instruments probe --null 200 --seed 101), is taken as
    // 1/f-like: it has no finite correlation time, and its lowest frequencies are indistinguishable
    // from an offset per stream that no AR model of a few hundred readings captures, so the level
    // of each stream becomes a nuisance parameter. Its slow wander within a test is modelled as a
    // random walk: AR(1) + walk by REML over what the current model and the levels leave
    // (core/noise_handling.hpp), once per round. Burg's AR(p) of a stream of a few hundred readings
    // misses that wander and took it for drifts (23 false findings in 200 1/f-like null sessions;
    // with the walk: bench/ diagnose_realistic_bench --rho -1).
    if (!R.J_levels.size()) {
      const Eigen::MatrixXd L = stream_levels(S.P);
      R.J_levels.resize(R.in.Jfree.rows(), R.in.Jfree.cols() + L.cols());
      R.J_levels << R.in.Jfree, L;
      R.levels_rank = static_cast<int>(orthonormal_basis(R.J_levels).cols() - C.Q_raw.cols());
    }
    if (!C.wander_noise.W) {
      C.wander_start = estimate_noise_model(S.layout, fit.residuals, options.noise);
      NoiseModel walk = S.cache.level_walk(C.model_key, C.wander_start, fit.residuals, R.J_levels);
      with_walk_bounded_by_declared(S.P, fit.residuals, walk);
      C.wander_noise = coloured_treatment(walk);
      with_hidden_levels(S.P, walk, C.wander_noise);
    }
    // The walk estimated with the candidate's columns in the model too, so that its own
    // signature is not taken for the walk (a drift or warm-up the current model leaves, whose
    // walk whitened it away: thermal_drift_Z and thermal_warmup_Z on the probe in AR(1) 0.9
    // noise, 'nothing' at 10x), where the candidate's own AR model of its residual is below
    // half the current one's sigma (it explains most of what the walk would take); the
    // round's best few are estimated so after the round (rescore_with_own_walk).
    round_walk = !(own_model.sigma_um < 0.5 * C.wander_start.sigma_um);
    own = round_walk ? C.wander_noise : walk_with_candidate(S, fit, R, C, Jc);
    // The levels: with a declared noise, each stream's level has the variance the declared
    // noise holds beyond what the model shows (with_hidden_levels, as in the final refit), so a
    // candidate that moves a whole stream (a probe's stylus_radius_offset) is judged against
    // it; without one, the level is unknown and a nuisance parameter.
    with_levels = !own.full;
  }
  if (round_walk) {
    std::optional<ScoringInputs>& in = C.wander_in[with_levels ? 1 : 0];
    if (!in) in = inputs_under(fit, R, own, with_levels);
    s = score_under(S, R, *in, c, Jc, own);
  } else {
    s = score_under(S, R, inputs_under(fit, R, own, with_levels), c, Jc, own);
  }
  judged_with = own;
}

// The candidates of a round judged under its 1/f-like walk (estimated without their columns)
// that are rescored under the walk estimated with them: the best few by delta BIC whose F-test
// under the round's walk is below kOwnWalkPrescreen, in a round none of whose candidates passes
// BIC by kOwnWalkMargin already. REML with an effect still in the residuals takes part of it
// for the walk and whitens it away: at 3x the half-detection amplitude in 1/f-like noise the
// hidden effect's delta BIC was -0.3 to -9.8 under the round's walk and -6 to -26 under its
// own (BC-trt ballbar, bench/diagnosis_confusion.py --noise pink --seed 211), where an oracle
// under the true covariance gives -12 to -28. Every candidate so (the pre-screen alone) took
// the effect sessions' CPU time 2.3x; a REML per candidate of the round was 8 s a diagnosis.
// Only where every stream has kOwnWalkMinStream readings: a walk estimated from what a
// candidate leaves of a short stream is lowered by the candidate that follows the noise's slow
// part, by more than the thresholds allow for (a probe session's 120 touches in 1/f-like
// noise: 1 of 200 null sessions gave a group, 0 without; bench/diagnosis_confusion.py
// --instruments probe --entries zzz_none --null 200 --seed 101). A ballbar test has 181-360
// readings, an R-test set-up 84 per channel.
constexpr double kOwnWalkPrescreen = 0.01;
constexpr std::size_t kOwnWalkCandidates = 3;
constexpr double kOwnWalkMargin = 30.0;
constexpr std::size_t kOwnWalkMinStream = 150;
// A kept candidate whose signature is at least this share a level and a slope per stream is
// rescored with the walk bounded by the declared variance of the readings themselves
// (VarianceBound::kMarginal) instead of their variation within the stream. REML's walk of
// 1/f-like ballbar readings, bounded within the stream, still had readings of 0.45-0.8 um^2
// (g0 + q^2 (n - 1) / 2) where 0.25 um^2 was declared, and with the hidden levels a test's mean
// varied by 0.4-0.7 um^2 where refsim's 1/f-like noise gives 0.085-0.10: a 10x thermal drift
// was taken for noise (delta BIC -3.7, -54 under the bound). Under the bound in every round (all
// candidates) harmonics were named alone against rivals that had been in their group, some
// wrongly (3 wrong in the first 30 sessions of seed 223): the bound takes the walk's share of
// the middle frequencies. So only here, for the kept few, all under one noise model
// (marginal_round_walk), with their rivals weighed under the round's kWithin walk too
// (name_finding). A share of 0.15 (0.3 until 12-07): the 1/f-like ballbar misses at 3x were
// harmonics of order 2-4, straightness, squareness and gravity sag with slow shares of 0.02-0.15
// whose truth ranked first at delta BIC +6 to -8.7 under the within-stream bound (seeds
// 223-239: 5.4-13.2 points below the oracle); with 0.15 and kMarginal's walk three quarters of the
// way to the marginal bound (hidden_levels.cpp), -0.8 to 3.1 points, 2 / 300 null sessions with a
// group.
constexpr double kSlowShare = 0.15;

bool streams_hold_own_walk(const NoiseStreamLayout& layout) {
  for (const std::vector<Eigen::Index>& rows : layout.rows)
    if (rows.size() < kOwnWalkMinStream) return false;
  return !layout.rows.empty();
}

struct OwnWalkCandidate {
  double delta_bic = 0.0;
  std::size_t score = 0, candidate = 0;
  Eigen::MatrixXd Jc;
};

// Keep `c` among the kOwnWalkCandidates best (lowest delta BIC) of `best`, in order.
void keep_best(std::vector<OwnWalkCandidate>& best, OwnWalkCandidate c) {
  if (best.size() == kOwnWalkCandidates && !(c.delta_bic < best.back().delta_bic)) return;
  const auto at =
      std::upper_bound(best.begin(), best.end(), c.delta_bic,
                       [](double d, const OwnWalkCandidate& b) { return d < b.delta_bic; });
  best.insert(at, std::move(c));
  if (best.size() > kOwnWalkCandidates) best.pop_back();
}

// The one noise model of a round's kept few under the marginal bound: AR(1) + walk by REML with
// all of their columns in the model beside the stream levels, bounded by the declared variance
// of the readings where what that model leaves does not vary beyond it. The same for each of
// them, so that none wins by its noise model: a walk by REML with each one's own columns could
// come out lowest for the most flexible one (a warm-up's time constant takes some of the noise's
// wander with it), which was then judged under the tightest model (h-pink10 at 3cd9f30, seed 300
// of test_ballbar_drift_in_one_over_f_noise_is_not_taken_for_the_noise: thermal_warmup_X -260.9,
// the drift -9.1, the warm-up named first with no parameter at 3 sigma). The round's walk (REML
// without them) instead keeps their signature in its AR(1) part, which the bound does not
// touch: a 10x thermal_drift_Z went from -9.8 to +3.2 under it, -62.4 under this one.
NoiseTreatment marginal_round_walk(const SearchContext& S, const ModelFit& fit, const Round& R,
                                   const ColouredRound& C,
                                   const std::vector<OwnWalkCandidate>& best) {
  Eigen::Index k = R.J_levels.cols();
  for (const OwnWalkCandidate& b : best) k += b.Jc.cols();
  Eigen::MatrixXd X(R.J_levels.rows(), k);
  X.leftCols(R.J_levels.cols()) = R.J_levels;
  k = R.J_levels.cols();
  for (const OwnWalkCandidate& b : best) {
    X.middleCols(k, b.Jc.cols()) = b.Jc;
    k += b.Jc.cols();
  }
  NoiseModel walk = estimate_noise_model_reml(C.wander_start, fit.residuals, X);
  const Eigen::MatrixXd Q = orthonormal_basis(X);
  with_walk_bounded_by_declared(S.P, fit.residuals - Q * (Q.transpose() * fit.residuals), walk,
                                VarianceBound::kMarginal);
  NoiseTreatment t = coloured_treatment(walk);
  with_hidden_levels(S.P, walk, t, VarianceBound::kMarginal);
  return t;
}

// The kept candidates rescored under the walk estimated with their own columns (see above), or,
// where one of them is slow (kSlowShare), all under the marginal bound of marginal_round_walk.
void rescore_with_own_walk(const SearchContext& S, const ModelFit& fit, Round& R,
                           const ColouredRound& C, const std::vector<OwnWalkCandidate>& best) {
  for (const Score& s : R.scores)
    if (s.delta_bic < S.options.min_delta_bic - kOwnWalkMargin) return;
  // One bound for all of them: a candidate rescored under the marginal bound beside a rival
  // rescored under the looser within-stream one won by the bound alone (h-pink9: a 10x
  // thermal_warmup_X named linear_squareness_ZX's group first, the drift rescored kWithin).
  VarianceBound bound = VarianceBound::kWithin;
  for (const OwnWalkCandidate& b : best)
    if (slow_share(S.layout, C.Q_raw, b.Jc) >= kSlowShare) bound = VarianceBound::kMarginal;
  const bool marginal = bound == VarianceBound::kMarginal;
  const NoiseTreatment shared =
      marginal ? marginal_round_walk(S, fit, R, C, best) : NoiseTreatment{};
  for (const OwnWalkCandidate& b : best) {
    const Effect& c = S.candidates[b.candidate];
    const NoiseTreatment own = marginal ? shared : walk_with_candidate(S, fit, R, C, b.Jc);
    // Under the marginal bound the levels are never free: a stream whose walk the bound lowered
    // holds the declared variance to the rounding, and whether that left a hidden level of
    // rounding size (the level as the walk's start gives it) or none (a free level parameter)
    // decided between a 10x ballbar_length_offset at -61.4 and unobservable (BC-trt, seed 223).
    const bool with_levels = !marginal && !own.full;
    Score s = score_under(S, R, inputs_under(fit, R, own, with_levels), c, b.Jc, own);
    if (!s.observable) continue;
    if (s.delta_bic < S.options.min_delta_bic) {
      s.X.resize(R.in.Jfree.rows(), R.in.Jfree.cols() + s.k);
      s.X << R.in.Jfree, b.Jc * s.directions;
    }
    R.scores[b.score] = std::move(s);
    R.treatment_of[b.score] = own;
    R.levels_of[b.score] = with_levels;
    if (marginal) R.named_under[b.score] = C.wander_noise;
  }
}

// The round's table (every observable candidate, best first) for D.rounds.
std::vector<CandidateScore> round_table(const Round& R, const ModelFit& fit) {
  std::vector<CandidateScore> table;
  for (const Score& s : R.scores) {
    // RMS after, in um: the whitened fraction applied to the raw RMS.
    const double frac = std::sqrt(s.rss1 / std::max(R.in.r_w.squaredNorm(), 1e-300));
    table.push_back({s.effect.id(), s.k, s.delta_bic, s.f_pvalue, rms_um(fit.residuals) * frac});
  }
  std::sort(table.begin(), table.end(), [](const CandidateScore& a, const CandidateScore& b) {
    return a.delta_bic < b.delta_bic;
  });
  return table;
}

}  // namespace

Round score_round(const SearchContext& S, const ModelFit& fit, const EffectModel& effects,
                  std::vector<bool>& done, bool first_round, Diagnosis& D) {
  const DiagnosisOptions& options = S.options;
  const std::vector<Effect>& candidates = S.candidates;
  const NoiseTreatment& noise = S.noise;
  Round R;
  R.in.Jfree = free_columns(fit.jacobian);
  R.in.Q_w = orthonormal_basis(noise.whiten(R.in.Jfree));
  R.in.r_w = noise.whiten(fit.residuals);
  R.in.num_free = fit.num_free;
  ColouredRound C;
  C.model_key = SearchCache::key(effects);
  C.own_noise = options.noise;
  if (noise.W) {
    C.Q_raw = orthonormal_basis(R.in.Jfree);
    C.Qr = C.Q_raw.transpose() * fit.residuals;
    if (S.model) C.own_noise.max_order = std::min(C.own_noise.max_order, S.model->max_order + 2);
    C.slow = lacks_declared_variance(S.P, fit);
  }
  // This round's candidate Jacobians at the current fit, in batches of at most
  // kChunkValues doubles: one batch for a session of a few thousand readings, and a long
  // session holds one batch at a time (the cache keeps what fits its limit).
  constexpr std::size_t kChunkValues = std::size_t{2} << 20;  // 16 MB
  const std::size_t rows = static_cast<std::size_t>(fit.residuals.size());
  std::vector<SharedMatrix> chunk_jc;
  std::vector<std::size_t> chunk_of(candidates.size(), SIZE_MAX);  // index in chunk_jc
  const auto jacobian_of = [&](std::size_t c) -> const Eigen::MatrixXd& {
    if (chunk_of[c] == SIZE_MAX) {
      std::vector<Effect> todo;
      std::size_t values = 0;
      for (std::size_t d = c; d < candidates.size(); ++d) {
        if (done[d] || !S.unresolved[d].empty()) continue;
        const std::size_t v = rows * static_cast<std::size_t>(candidates[d].num_params());
        if (!todo.empty() && values + v > kChunkValues) break;
        chunk_of[d] = todo.size();
        todo.push_back(candidates[d]);
        values += v;
      }
      chunk_jc.clear();  // the previous batch goes before the next is made
      chunk_jc = S.cache.candidate_jacobians(S.P, effects, fit, todo);
    }
    return *chunk_jc[chunk_of[c]];
  };
  std::vector<OwnWalkCandidate> own_walk;  // rescored under their own walk after the round
  const bool rescore_own_walk = noise.W && streams_hold_own_walk(S.layout);
  int round_total = 0, round_done = 0;  // candidates to score in this round (progress)
  for (std::size_t c = 0; c < candidates.size(); ++c)
    round_total += !done[c] && S.unresolved[c].empty();
  const std::string stage =
      std::string(noise.W ? "search with the noise model" : "search (white noise)") + ", round " +
      std::to_string(D.rounds.size() + 1);
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (done[c]) continue;
    if (!S.unresolved[c].empty()) {
      D.unobservable.push_back({candidates[c].id(), S.unresolved[c]});
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
    bool with_levels = false, round_walk = false;
    if (!noise.W)
      s = score(R.in, candidates[c], noise.whiten(Jc), options.min_visible_chi2,
                options.min_delta_bic);
    else
      score_coloured(S, fit, R, C, candidates[c], Jc, s, judged_with, with_levels, round_walk);
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
      s.X.resize(R.in.Jfree.rows(), R.in.Jfree.cols() + s.k);
      s.X << R.in.Jfree, Jc * s.directions;
    }
    if (rescore_own_walk && round_walk && s.f_pvalue < kOwnWalkPrescreen)
      keep_best(own_walk, {s.delta_bic, R.scores.size(), c, Jc});
    R.round_bic.push_back(s.delta_bic);
    R.scores.push_back(std::move(s));
    R.treatment_of.push_back(judged_with);
    R.levels_of.push_back(with_levels);
  }
  if (!own_walk.empty()) rescore_with_own_walk(S, fit, R, C, own_walk);
  if (options.progress) options.progress(stage, round_total, round_total);
  D.rounds.push_back(round_table(R, fit));
  return R;
}

}  // namespace rotacal::diagnosis_detail
