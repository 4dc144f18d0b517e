// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: the pieces of the diagnosis search (diagnosis.cpp, the loop and its
// entry point): how the noise enters every decision, what the searches of one diagnosis share,
// one round's scoring of the candidates (search_round.cpp), the choice and naming of a
// finding (selection.cpp) and the test of what the final model leaves (final_test.cpp).

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rotacal/core/noise_handling.hpp"
#include "rotacal/diagnose/diagnosis.hpp"
#include "scoring.hpp"

namespace rotacal::diagnosis_detail {

// How the noise enters every decision: white with one sigma, or whitened by an AR model.
struct NoiseTreatment {
  double sigma_mm = 0.0;  // white: the sigma; coloured: the marginal sigma (for wording)
  std::string source;
  std::shared_ptr<const ArWhitener> W;  // null: white
  // Coloured, when set: W and more (the final refit's hidden stream levels, diagnosis.cpp),
  // the whitener every decision under this treatment uses instead of W.
  std::shared_ptr<const ResidualWhitener> full;
  Eigen::MatrixXd whiten(const Eigen::MatrixXd& M) const {
    if (!W) return M / sigma_mm;
    Eigen::MatrixXd out = M;
    if (full)
      full->apply(out);
    else
      W->apply(out);
    return out;
  }
};

NoiseTreatment white_treatment(const DiagnosisProblem& P, const ModelFit& baseline);
/// `described`: with the model's summary as the source (the candidates' own models and the
/// structure test's are never reported, and formatting a summary per candidate is wasted).
NoiseTreatment coloured_treatment(const NoiseModel& m, bool described = true);

/// What the declared variance bounds (hidden_levels.cpp): the model's variation within each
/// stream (kWithin), or the mean of its readings' variances, walk and level included (kMarginal;
/// the walk's step squared three quarters of the way from the within-stream bound's to it).
enum class VarianceBound { kWithin, kMarginal };

/// `t` with the stream levels of `m` (the model t.W whitens by) that its residuals cannot show,
/// against the declared noise (hidden_levels.cpp): t.full set where any stream lacks variance;
/// unchanged without a declared noise.
void with_hidden_levels(const DiagnosisProblem& P, const NoiseModel& m, NoiseTreatment& t,
                        VarianceBound bound = VarianceBound::kWithin);

/// Each stream's random-walk step of `m` lowered so that its variation within the stream is at
/// most the declared variance (hidden_levels.cpp); unchanged without a declared noise, and on a
/// stream whose `residuals` vary beyond what the declared noise allows.
void with_walk_bounded_by_declared(const DiagnosisProblem& P, const Eigen::VectorXd& residuals,
                                   NoiseModel& m, VarianceBound bound = VarianceBound::kWithin);

/// Whether the declared noise holds variance that `fit`'s residuals lack: |r|^2 / noise_um^2
/// below the kLacksDeclaredVariance quantile of chi-square(n - free parameters), which white
/// noise of the declared size would leave. Then the fit has taken a part of the noise into its
/// parameters, i.e. the noise is slow (1/f-like: its slowest parts follow the fitted
/// directions) in a way no model of these residuals shows (hidden_levels.cpp). False without a
/// declared noise.
inline constexpr double kLacksDeclaredVariance = 1e-3;
bool lacks_declared_variance(const DiagnosisProblem& P, const ModelFit& fit);

// One indicator column per noise stream (group, channel).
// One level per noise stream, shared by the runs of one test (radial_C, radial_C_cw,
// radial_C_f2000, test_of_run): they follow each other with the bar in place, so a wander does
// not start afresh between them, and a step between them (backlash, servo lag) is a signal.
// A label is taken for a run only where the test it names is itself a group of the session
// (a user's "sphere_f1" or an R-test set-up "nest_cw" keeps its own level).
Eigen::MatrixXd stream_levels(const DiagnosisProblem& P);

// A thermal_warmup candidate's Jacobian at its amplitude 0 has a zero time-constant column:
// filled with the tangent of its shift at a unit amplitude (time_constants.cpp).
void with_time_constant_tangent(const DiagnosisProblem& P, const Effect& candidate,
                                Eigen::MatrixXd& J);

// The effect's parameters in a fit (named "id" or "id.name").
std::vector<ParameterEstimate> parameters_of(const ModelFit& fit, const Effect& effect);

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
  // Per model: the AR(1) + random walk of its residuals by REML, stream levels beside its free
  // columns, from the residuals' AR model. The 1/f-like round at a model (search_round.cpp) and
  // the remainder's test of that model as final (final_test.cpp) estimate the same, and REML is
  // most of a 1/f-like diagnosis' time.
  std::map<std::string, NoiseModel> level_walks;
  // Group members a previous pass's final GLS left with no parameter determined where the model
  // held them (DiagnosisOptions::hold_by_weight; diagnosis.cpp, diagnose): the model member rule
  // passes over them, as over any undetermined member (model_member.hpp), so that the next member
  // by weight is held rather than the finding dropped. Kept with the fits the next pass reuses.
  std::set<std::string> not_held;
  // The last search's picks, one per finding (the best-scoring member of its group that passed
  // the search's tests), in the findings' order: where the model holds another member, the
  // decisions that weigh every finding (white or coloured noise, the noise level of the white
  // search) are judged on the picks' model, so that the names do not hang on which member is
  // held (diagnosis.cpp).
  EffectModel picks;

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
  // The level walk (above) of model key `k`, whose fit left `residuals`; `J_levels`: its free
  // columns and the stream levels; `start`: the AR model of `residuals`.
  const NoiseModel& level_walk(const std::string& k, const NoiseModel& start,
                               const Eigen::VectorXd& residuals, const Eigen::MatrixXd& J_levels) {
    auto it = level_walks.find(k);
    if (it == level_walks.end())
      it = level_walks.emplace(k, estimate_noise_model_reml(start, residuals, J_levels)).first;
    return it->second;
  }
  // The Jacobians of `todo` at `at` (the fit of model `m`).
  std::vector<SharedMatrix> candidate_jacobians(const DiagnosisProblem& P, const EffectModel& m,
                                                const ModelFit& at,
                                                const std::vector<Effect>& todo) {
    std::map<std::string, SharedMatrix>& known = jacobians[key(m)];
    std::vector<Effect> missing;
    for (const Effect& c : todo)
      if (!known.count(c.id())) missing.push_back(c);
    // Nothing to compute where every one is known (a finding's field, asked after its round):
    // the ballbar's chain rule would still evaluate the fit's part of every row first.
    std::vector<Eigen::MatrixXd> fresh;
    if (!missing.empty()) fresh = P.candidate_jacobians(at, missing);
    for (std::size_t i = 0; i < missing.size(); ++i)
      with_time_constant_tangent(P, missing[i], fresh[i]);
    std::vector<SharedMatrix> out;
    for (const Effect& c : todo) {
      const auto it = known.find(c.id());
      if (it != known.end()) {
        out.push_back(it->second);
        continue;
      }
      const std::size_t i =
          static_cast<std::size_t>(std::find(missing.begin(), missing.end(), c) - missing.begin());
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

/// What one search holds fixed over its rounds.
struct SearchContext {
  const DiagnosisProblem& P;
  const DiagnosisOptions& options;
  const std::vector<Effect>& candidates;
  const std::vector<std::string>& unresolved;  ///< per candidate: why its order is not resolved
                                               ///< (empty: it is; then it is scored)
  const NoiseTreatment& noise;                 ///< the search's noise treatment
  const NoiseModel* model;                     ///< the search's noise model (null: white)
  const NoiseTreatment& white;
  const NoiseStreamLayout& layout;  ///< every noise model of this search
  SearchCache& cache;
};

/// How many sigma from zero the best-determined combination of `effect`'s observable free
/// parameters is in `refit` under noise treatment t (selection.cpp).
double determined_sigmas(const ModelFit& refit, const Effect& effect, const NoiseTreatment& t);
/// How many sigma from zero the best-determined single parameter of `effect` is in `refit`
/// (selection.cpp): issue 29's rule 6 as the model member must meet it (model_member.hpp).
double parameter_sigmas(const ModelFit& refit, const Effect& effect, const NoiseTreatment& t);

/// One round: every candidate not yet done scored against the current model.
struct Round {
  ScoringInputs in;           ///< the current model under the search's noise treatment
  Eigen::MatrixXd J_levels;   ///< coloured: the free columns and one level column per stream
                              ///< (only when a 1/f-like candidate needed them; else empty)
  int levels_rank = 0;        ///< what the level columns add to the model's rank
  std::vector<Score> scores;  ///< the observable candidates
  std::vector<NoiseTreatment> treatment_of;  ///< per score: the noise it was judged with
  std::vector<bool> levels_of;               ///< per score: judged with the stream levels
  /// Per score rescored under the marginal bound (search_round.cpp): the round's walk under the
  /// within-stream bound, what its finding's rivals are weighed under too (name_finding). The
  /// marginal bound takes the walk's share of the middle frequencies too, where rivals such as
  /// linear_scale_X and _Y differ: under it a 3x linear_scale_Y was named [linear_scale_X,
  /// angular_error_BX, angular_error_AY], the truth 22 behind (h-pink10).
  std::map<std::size_t, NoiseTreatment> named_under;
  std::vector<double> round_bic;  ///< per score: its delta BIC as first scored, before
                                  ///< any rescoring under its own walk
};

/// Score every candidate not `done` against `fit` (the fit of `effects`). Candidates that are
/// unresolved, undefined on the readings or not visible are marked done (and, in the first
/// round, reported unobservable in D); the round's table is appended to D.rounds.
Round score_round(const SearchContext& S, const ModelFit& fit, const EffectModel& effects,
                  std::vector<bool>& done, bool first_round, Diagnosis& D);

/// The candidate a round adds: the best that passes the F-test (Bonferroni) and BIC, predicts
/// left-out blocks better and whose refit determines a parameter; null: none.
struct Choice {
  const Score* chosen = nullptr;
  const ModelFit* refit = nullptr;  ///< of the extended model, held by the cache
  double cv_before = 0.0, cv_after = 0.0;
  const std::vector<int>* fold = nullptr;  ///< the search's cross-validation blocks
};
/// Blocked cross-validated RMS (um) of the residuals of `fit` before and after adding the
/// columns X = [the model's free columns, a candidate's], on blocks as long as the noise's
/// correlation as `refit` (the extended model) leaves it, or `fold` in white noise.
std::pair<double, double> cross_validated(const SearchContext& S, const Round& R,
                                          const Eigen::MatrixXd& X, const ModelFit& fit,
                                          const ModelFit& refit, const std::vector<int>& fold);
/// Whether candidate s of round R (scored at `fit`; `refit`: the extended model's fit) still
/// passes the F-test (alpha / m_tests) and BIC with each noise stream taken as AR(1) at the
/// upper z-sigma bound of its lag-1 correlation estimated on refit's residuals, z =
/// P.correlation_bound_z() (correlation_bound.cpp). True where z is 0 and for a candidate judged
/// under the 1/f-like treatment.
bool holds_at_correlation_bound(const SearchContext& S, const Round& R, const Score& s,
                                const ModelFit& fit, const ModelFit& refit, double m_tests);

Choice choose(const SearchContext& S, const Round& R, const ModelFit& fit,
              const EffectModel& effects, const std::vector<int>& fold, std::vector<bool>& done,
              Diagnosis& D);

/// The finding of `choice` against the round R scored at `before` (the fit of `before_effects`):
/// its weight among its rivals, its group, and the ambiguity it leaves (appended to D).
/// The finding holds the member of its group that the extended model holds (model_member.hpp);
/// none (reported unobservable in D, with why) where no member's parameters are determined.
std::optional<Finding> name_finding(const SearchContext& S, const Round& R, const Choice& choice,
                                    const ModelFit& before, const EffectModel& before_effects,
                                    Diagnosis& D);

/// A thermal_warmup's time constant the final fit held, profiled, with its uncertainty in the
/// other parameters' sigmas (time_constants.cpp); `scale`: what the caller multiplies them by.
void profile_time_constants(const DiagnosisProblem& P, const NoiseTreatment& t, double scale,
                            Diagnosis& D);

/// What the final model leaves: structure after, the unexplained-structure test and, where
/// structure remains as a function of one rotary angle, its per-angle table (into D).
void judge_remainder(const SearchContext& S, const ModelFit& final_fit, Diagnosis& D);

/// Structure the noise model took for noise (issue 50 item 4), judged on D's final residuals and
/// D.noise (final_test.cpp): the noise levels of one instrument's channels differ (a step-down
/// F-test at 1 %, Bonferroni over the channels, each channel's degrees of freedom divided by the
/// scatter its correlation gives its variance), or a stream of fewer than 200 readings took the
/// largest AR order allowed. Where either holds, D.unexplained says so, with where the
/// structure is largest, how large beyond the quiet channels' noise, and the test to resolve it.
void judge_noise_structure(const DiagnosisProblem& P, const DiagnosisOptions& options,
                           Diagnosis& D);

}  // namespace rotacal::diagnosis_detail
