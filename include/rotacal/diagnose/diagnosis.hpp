// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Diagnosis: show what the fitted model gets wrong, name the physical cause from the
/// catalogue (../shared/spec/effects.md), extend the model with it, measure the gain.
///
/// The engine is independent of the instrument. A `DiagnosisProblem` (ballbar_diagnosis.hpp,
/// rtest_diagnosis.hpp) supplies the nonlinear fit of baseline + effects and each candidate's
/// Jacobian; the engine does the statistics:
///  1. baseline fit; adequacy by chi-square against the noise (declared in the file, or
///     estimated from successive differences, which smooth systematic errors barely affect);
///  2. residual structure per group (test or nest): RMS, harmonics in the rotary angle (only
///     the orders its angular sampling resolves, see HarmonicResolution), trend;
///  3. every candidate scored by a linearised refit from the current model (the model is
///     linear in um/urad-sized parameters to far below the noise): delta BIC, F-test with a
///     Bonferroni correction over the candidates, and blocked cross-validation (contiguous
///     blocks of each group left out in turn, so the extension must predict unseen angles);
///  4. the best significant candidate is added, the model refitted (nonlinear), and 3 repeats
///     until nothing significant is left;
/// Files: diagnosis.cpp (the search loop, the final GLS refit), search_round.cpp (one round's
/// scoring), selection.cpp (the choice of a finding, its rivals and group), rivals.cpp
/// (posterior weights), final_test.cpp (what the final model leaves), scoring.cpp (linearised
/// refit, F/BIC, cross-validation), harmonics.cpp (what the angular sampling resolves),
/// residual_structure.cpp (per-group structure, noise), ambiguity.cpp (separating tests).
///  5. candidates the data cannot see, and *_hn candidates of an order the sampling of their
///     axis cannot resolve (aliased), are reported unobservable; candidates that explain the
///     data as well as the chosen one are reported ambiguous; significant structure that is
///     left is reported unexplained with its signature.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/core/whitener.hpp"
#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

/// A nonlinear fit of baseline + effects, as the engine sees it.
struct ModelFit {
  EffectModel effects;
  std::vector<ParameterEstimate> parameters;  ///< baseline parameters first, then the effects'
  Eigen::VectorXd residuals;                  ///< measured - model, mm, one per scalar reading
  Eigen::MatrixXd jacobian;                   ///< d model / d parameter (mm per unit), free columns
                                              ///< only (fixed ones are zero)
  int num_free = 0;                           ///< parameters actually estimated
  /// The parameters the fit held (zero columns of `jacobian`) and the model's derivative in
  /// each there, one column per held parameter: in a diagnosis of several sessions
  /// (multi_session.hpp) another session may determine them. Empty where none is held.
  std::vector<Eigen::Index> held;
  Eigen::MatrixXd held_columns;
  /// Zero the held columns of `jacobian`, keeping them in held / held_columns.
  void hold(const std::vector<bool>& is_held) {
    held.clear();
    for (std::size_t j = 0; j < is_held.size(); ++j)
      if (is_held[j]) held.push_back(static_cast<Eigen::Index>(j));
    held_columns.resize(jacobian.rows(), static_cast<Eigen::Index>(held.size()));
    for (std::size_t i = 0; i < held.size(); ++i) {
      held_columns.col(static_cast<Eigen::Index>(i)) = jacobian.col(held[i]);
      jacobian.col(held[i]).setZero();
    }
  }
};

/// What the engine needs from an instrument.
class DiagnosisProblem {
 public:
  virtual ~DiagnosisProblem() = default;
  virtual MachineType machine() const = 0;
  /// The instrument, as `rotacal design` names it ("ballbar", "rtest", "probe"): the design
  /// command a finding of this session points to.
  virtual std::string instrument() const = 0;
  /// Group (test label or nest) of each scalar reading.
  virtual const std::vector<std::string>& groups() const = 0;
  /// Time (s) of each reading, and the rotary angles (rad) at it.
  virtual const std::vector<double>& times() const = 0;
  virtual const std::vector<RotaryAngles<double>>& angles() const = 0;
  virtual std::optional<double> declared_noise_um() const = 0;
  /// Catalogue entries this instrument could see at all (e.g. R-test: no ballbar_* entries).
  virtual std::vector<Effect> candidates(int max_harmonic) const = 0;
  /// Full nonlinear fit of the baseline extended by `effects`.
  virtual ModelFit fit(const EffectModel& effects) const = 0;
  /// The same fit by GLS under `noise` (one residual per scalar reading, in reading order):
  /// the final model's numbers when the noise is correlated.
  virtual ModelFit fit_gls(const EffectModel& effects,
                           std::shared_ptr<const ResidualWhitener> noise) const = 0;
  /// d model / d (parameters of `candidate`) at `at`, one row per reading.
  virtual Eigen::MatrixXd candidate_jacobian(const ModelFit& at, const Effect& candidate) const = 0;
  /// candidate_jacobian of each of `candidates`, in order; an instrument may share work
  /// between them (the ballbar: one evaluation per harmonic kind and axis).
  virtual std::vector<Eigen::MatrixXd> candidate_jacobians(
      const ModelFit& at, const std::vector<Effect>& candidates) const {
    std::vector<Eigen::MatrixXd> out;
    out.reserve(candidates.size());
    for (const Effect& c : candidates) out.push_back(candidate_jacobian(at, c));
    return out;
  }
  /// candidate_jacobians handed to `visit(index, jacobian)` one at a time, so that a caller
  /// needing each once (the uncertainty budget of a long session) never holds them all.
  virtual void visit_candidate_jacobians(
      const ModelFit& at, const std::vector<Effect>& candidates,
      const std::function<void(std::size_t, const Eigen::MatrixXd&)>& visit) const {
    const std::vector<Eigen::MatrixXd> all = candidate_jacobians(at, candidates);
    for (std::size_t i = 0; i < all.size(); ++i) visit(i, all[i]);
  }
  /// visit_candidate_jacobians on a reduced design of about `rows` rows (every k-th row and
  /// both sides of every break where an effect may jump), interpolated linearly to every row
  /// between them: for smooth effects of a long session (the uncertainty budget's type B).
  /// The default evaluates every row.
  virtual void visit_candidate_jacobians_reduced(
      const ModelFit& at, const std::vector<Effect>& candidates, std::size_t rows,
      const std::function<void(std::size_t, const Eigen::MatrixXd&)>& visit) const {
    (void)rows;
    visit_candidate_jacobians(at, candidates, visit);
  }
  /// The group names of a complete standard test for this machine and instrument, and the
  /// candidate Jacobian on it (used to name the test that separates two ambiguous
  /// candidates). Empty if the instrument has no standard test.
  virtual std::vector<std::string> reference_groups() const { return {}; }
  /// The mean commanded xyz (mm) of the session: a_ref of the linear-axis polynomials
  /// (straightness_DA, angular_error_*). Default: zero (then those polynomials are about 0).
  virtual Eigen::Vector3d mean_commanded_xyz() const { return Eigen::Vector3d::Zero(); }
  /// z of the upper confidence bound of each noise stream's lag-1 correlation at which a
  /// finding must hold too (src/diagnose/correlation_bound.cpp); 0: not judged there.
  /// An instrument whose noise is one short stream sets it: the estimate's spread there makes a
  /// slow shape a finding whenever the session's correlation comes out low.
  virtual double correlation_bound_z() const { return 0.0; }
  /// The name of the k-th reading that shares a time stamp in a group (a noise stream's channel,
  /// core/noise_model.hpp), as a message names it: an R-test's "dx", "dy", "dz".
  virtual std::string channel_name(int channel) const {
    return "channel " + std::to_string(channel + 1);
  }
  virtual Eigen::MatrixXd reference_jacobian(const ModelFit& /*at*/, const Effect& /*c*/,
                                             std::vector<std::string>* /*row_groups*/) const {
    return {};
  }
};

struct DiagnosisOptions {
  int max_harmonic = 4;        ///< harmonic orders tried for the *_hn entries
  int max_findings = 4;        ///< stop after this many effects
  double alpha = 0.01;         ///< family-wise false-finding rate per step (Bonferroni)
  double min_delta_bic = -10;  ///< "very strong" evidence on the Kass-Raftery scale
  int cv_blocks = 5;           ///< contiguous blocks per group for cross-validation
  /// A cause is named alone only when its posterior weight among itself and its rivals (the
  /// observable candidates of its round, passed or not, whose fitted signatures correlate with
  /// its own by at least rival_correlation) is at least min_weight, at BIC's Occam term of
  /// ln n per parameter and at AIC's of 2 alike (src/diagnose/rivals.hpp: the smaller of the
  /// two weights); otherwise the finding is the group of candidates, best first, that holds
  /// min_weight together, with every rival a member cannot be told apart from ("one of
  /// these"), and those are reported as ambiguous. 0.9: the chosen cause is 9 times as
  /// probable as all its rivals together (a margin of 2 ln 9 = 4.4 over a single rival).
  double min_weight = 0.9;
  double rival_correlation = 0.5;
  /// A finding has at least one combination of its parameters determined to this many sigma
  /// from zero in its refit (sqrt(v^T C^-1 v) of its observable parameters: a single one at
  /// |value| >= k std, or correlated coefficients jointly); a candidate whose refit determines
  /// none is reported unobservable, not named.
  double min_determined_sigma = 3.0;
  /// Which member of a group finding the extended model holds (issue 50 item 3;
  /// src/diagnose/model_member.hpp). True: the member of the highest weight with a single
  /// parameter determined to min_determined_sigma and beside which the location errors stay
  /// determined (none's sigma more than 10x the model's before it), in the search's refit and
  /// again in the final numbers (by GLS under the final noise model, time constants profiled:
  /// one that is not is passed over and the search run again); a nested member within delta
  /// BIC 2 of it; or none (the baseline). Finding::model_reason says which and why. False: the
  /// search's pick, the best-scoring member that passed its tests, with what the weights say
  /// beside it in Finding::model_reason.
  bool hold_by_weight = true;
  std::vector<std::string> only;  ///< restrict candidates to these ids (empty: all)
  /// A candidate is visible when moving its parameters by plausible sizes (1 mm, 1 mrad, 1 um/s,
  /// 1e-3 for ratios, 10 um for a probe's lobing) beyond what the model absorbs changes
  /// chi-square by at least this much (25: a 5-sigma change); others are reported unobservable.
  double min_visible_chi2 = 25.0;
  /// A *_hn candidate is scored only if its axis' sampled angles resolve order n (see
  /// HarmonicResolution) with at least this new content: below it the order aliases onto the
  /// lower ones (C every 30 deg: order 7 takes the values of order 5) and is reported
  /// unobservable. Lenient on purpose: how well a resolvable order stands apart from the
  /// others is judged with the noise, by the F-test, cross-validation and the ambiguity report.
  double min_harmonic_new_content = 0.01;
  /// Estimate the residual noise's correlation (core/noise_model.hpp) from the baseline
  /// residuals and, when it is not white, make every decision on whitened residuals and
  /// Jacobians (F, BIC, visibility), cross-validate with blocks at least one correlation time
  /// long and test for unexplained structure against it. False: treat the noise as white.
  bool model_noise = true;
  /// Called after each candidate of a search round is scored (empty: silent): `stage` names
  /// the search and round, `done` of `total` counts that round's candidates. A 10-minute
  /// recording at 1 kHz takes tens of seconds; the CLI draws it as a progress bar.
  std::function<void(const std::string& stage, int done, int total)> progress;
  NoiseModelOptions noise = [] {
    NoiseModelOptions o;
    o.pooled = true;  // one set of AR coefficients per session: see NoiseModelOptions::pooled
    o.pool_only_if_all_coloured = true;
    return o;
  }();
};

/// Which harmonic orders of one rotary angle a set of readings resolves.
///
/// The design [1, cos k th, sin k th] (k = 1..max_order) is taken at the distinct angles
/// (angles within 0.05 deg merged, each row weighted by the square root of its number of
/// readings, so it has the normal matrix of the fit over all readings), with the columns scaled
/// so that an evenly sampled full turn makes them orthonormal. The "new content" of order k is
/// the smaller singular value of its (cos, sin) pair once the span of orders 0..k-1 is
/// projected out: 1 for an even full turn, 1/sqrt(variance inflation) of the pair in general,
/// 0 when the pair is rank-deficient against the lower orders. With N evenly spaced distinct
/// angles over a full turn, order k has new content 1 for k < N/2 and 0 from N/2 on (Nyquist:
/// order N/2 has a vanishing sine, order N-k takes the values of order k).
struct HarmonicResolution {
  char axis = 0;                    ///< angle the orders are in ('A', 'B' or 'C')
  int max_order = 0;                ///< orders asked for
  int distinct_angles = 0;          ///< after merging angles within 0.05 deg
  double span_deg = 0.0;            ///< the smallest arc holding every angle, deg
  double even_step_deg = 0.0;       ///< step of an evenly spaced full turn, deg (0: uneven)
  double min_new_content = 0.0;     ///< threshold used
  std::vector<double> new_content;  ///< of orders 1..max_order
  int resolved = 0;                 ///< orders 1..resolved all have new content >= threshold
  /// Why `order` (resolved < order <= max_order) is left out, in words.
  std::string why_not(int order) const;
};

/// Resolution of harmonic orders 1..max_order in `angles_rad` (one per reading, any turn).
/// Throws InvalidArgument if max_order < 0 or min_new_content is not in (0, 1].
HarmonicResolution resolve_harmonics(const std::vector<double>& angles_rad, char axis,
                                     int max_order, double min_new_content);

/// Residual structure of one group.
struct GroupResidual {
  std::string group;
  std::size_t n = 0;
  double rms_um = 0.0;
  double mean_um = 0.0;
  char angle_axis = 0;                  ///< the rotary axis that varies in the group (0: none)
  std::vector<double> harmonic_um;      ///< amplitude of orders 1..K in that angle, um: only
                                        ///< when it sweeps a full turn, and only the orders its
                                        ///< sampling resolves (K <= 8; empty otherwise)
  std::vector<int> harmonics_left_out;  ///< orders K+1..8 not fitted: the sampling cannot
                                        ///< resolve them (no amplitude is given for them)
  std::string harmonic_note;            ///< why harmonics were left out, in words (empty if none)
  double trend_um_per_s = 0.0;          ///< least-squares slope against time
};

struct Gain {
  double rms_before_um = 0.0;
  double rms_after_um = 0.0;
  double delta_bic = 0.0;
  double cv_rms_before_um = 0.0;
  double cv_rms_after_um = 0.0;
  double f_pvalue = 1.0;
};

/// A rival of a finding: a candidate of its round that explains the same signal.
struct Alternative {
  std::string effect;
  double weight = 0.0;       ///< posterior weight among the finding and its rivals (min_weight)
  double delta_bic = 0.0;    ///< BIC(this) - BIC(the finding's effect); > 0: fits worse
  double correlation = 0.0;  ///< |cosine| of the two fitted signatures
  bool in_group = false;     ///< one of the group the data cannot separate
  /// A harmonic of the finding's axis of an order this session's sampling cannot resolve (it
  /// takes the values of lower orders at the sampled angles): not scored, so its weight is 0
  /// and unknown, but it is in the group, since the data cannot exclude it.
  bool aliased = false;
};

struct Finding {
  /// The member of its group the extended model holds (src/diagnose/model_member.hpp): the
  /// search's pick, or with DiagnosisOptions::hold_by_weight the member the weights say.
  Effect effect;
  std::string model_reason;  ///< why the model holds `effect`, in words
  std::string cause;
  /// Posterior weight of `effect` among itself and its rivals (DiagnosisOptions::min_weight:
  /// the smaller of its BIC and AIC weights); below DiagnosisOptions::min_weight
  /// the finding is the group of `rivals` with in_group set, not `effect` alone.
  double weight = 1.0;
  std::vector<Alternative> rivals;  ///< best first
  /// Non-empty: its signature confined to a few consecutive poses and zero elsewhere (a local
  /// defect, outside the catalogue) fits the readings about as well, in words (the probe:
  /// src/diagnose/local_structure.hpp); `weight` then counts that local rival, and the finding
  /// is never named alone.
  std::string lack_of_fit;
  bool named_alone() const {
    if (!lack_of_fit.empty()) return false;
    for (const Alternative& a : rivals)
      if (a.in_group) return false;
    return true;
  }
  std::vector<ParameterEstimate> parameters;  ///< of the effect, from the final fit
  Gain gain;
  /// Baseline parameters that moved by more than their uncertainty once the effect was
  /// modelled: what the baseline got wrong about the machine. (name, before, after, unit)
  struct Shift {
    std::string name;
    double before = 0.0;
    double after = 0.0;
    double std_after = 0.0;
    std::string unit;
  };
  std::vector<Shift> shifts;
};

struct Ambiguity {
  std::vector<std::string> effects;  ///< ids that explain the data equally well
  double delta_bic = 0.0;            ///< BIC(other) - BIC(chosen)
  double correlation = 0.0;          ///< of their fitted signatures
  std::string separating_test;       ///< where their predictions differ most, in words
};

struct UnobservableEffect {
  std::string effect;
  std::string reason;
};

struct Unexplained {
  bool present = false;
  double chi2_per_dof = 0.0;  ///< of the whitened final residuals
  double p_value = 1.0;       ///< white noise: chi-square test; coloured: the structure test
  std::string signature;      ///< the strongest remaining structure, in words
  /// Where (coloured noise: the group whose structure test fails; white: the group with the
  /// largest residual), and the range of its swept angle where the residual is largest.
  std::string group;
  char axis = 0;            ///< swept rotary axis of that group (0: none; range in time)
  double range_from = 0.0;  ///< deg (or s when axis == 0)
  double range_to = 0.0;
  /// Structure the noise model took for noise (issue 50 item 4; src/diagnose/final_test.cpp),
  /// in words: the noise levels of one instrument's channels differ (F-test at 1 %), or a
  /// stream of fewer than 200 readings got the largest AR order allowed. Empty: neither.
  std::string noise_structure;
  double noise_structure_p = 1.0;  ///< the channels' F-test (Bonferroni), 1 where not applied
  double size_um = 0.0;            ///< RMS beyond the noise where that structure is largest, um
  double at = 0.0;                 ///< where it is largest: deg (or s when axis == 0)
  double noise_um = 0.0;           ///< the instrument's noise without it (its quiet channels), um
  std::string suggested_test;      ///< the test that would resolve it, in words
};

/// Structure outside the catalogue as a function of one rotary angle: a non-parametric table of
/// the error motion the instrument sees in one group (the mean residual of its reading per
/// commanded angle: along the bar for a ballbar, the probe displacement for an R-test), what
/// a controller's compensation table for that axis would hold, offered as a finding with its
/// gain.
struct AngleTable {
  std::string group;
  char axis = 0;                  ///< the rotary axis the table is in
  std::vector<double> angle_deg;  ///< bin centres (the distinct commanded angles when <= 72)
  std::vector<double> value_um;   ///< mean residual per bin
  std::vector<double> std_um;     ///< its standard error under the noise model
  std::vector<int> count;         ///< readings per bin
  /// rms over the whole session before/after subtracting the table; delta BIC and F on the
  /// noise model's effective samples; cross-validation by blocks of the group (bin means from
  /// the other blocks).
  Gain gain;
};

/// The per-angle table of `group` for `residuals` (mm); throws InvalidArgument if the group does
/// not exist or sweeps no rotary angle.
AngleTable angle_table(const DiagnosisProblem& problem, const Eigen::VectorXd& residuals,
                       const std::string& group, const NoiseModel& noise, double noise_um,
                       int cv_blocks = 5);

/// How one candidate scored against a model (linearised refit).
struct CandidateScore {
  std::string effect;
  int visible_params = 0;  ///< parameter directions the data can see
  double delta_bic = 0.0;
  double f_pvalue = 1.0;
  double rms_after_um = 0.0;
};

struct Diagnosis {
  MachineType machine = MachineType::AC_trt;
  struct Baseline {
    double residual_rms_um = 0.0;
    double noise_um = 0.0;
    std::string noise_source;  ///< "declared" or "estimated from successive differences"
    double chi2_per_dof = 0.0;
    double p_value = 1.0;  ///< P(chi2 >= observed) if the baseline were adequate
    std::size_t n = 0;
    int dof = 0;
  } baseline;
  std::vector<GroupResidual> structure_before;
  std::vector<GroupResidual> structure_after;
  std::vector<Finding> findings;  ///< in the order they were added
  /// Every observable candidate scored against each model in turn (rounds[0]: baseline),
  /// best first.
  std::vector<std::vector<CandidateScore>> rounds;
  std::vector<Ambiguity> ambiguous;
  std::vector<UnobservableEffect> unobservable;
  Unexplained unexplained;
  /// The residual noise model the decisions were made with (estimated from the residuals of
  /// the final model, after findings). white(): the noise was treated as white with
  /// baseline.noise_um.
  NoiseModel noise;
  bool noise_whitened = false;  ///< decisions made on AR-whitened residuals
  /// When unexplained structure remains in a group that sweeps a rotary angle: its per-angle
  /// table, offered as the extension (empty otherwise).
  std::vector<AngleTable> angle_tables;
  ModelFit baseline_fit;  ///< without its Jacobian (n x p, which a long session cannot keep twice)
  ModelFit final_fit;
  double seconds = 0.0;  ///< wall time of the diagnosis
};

/// Run the diagnosis. Throws InvalidArgument for unknown ids in options.only.
Diagnosis diagnose(const DiagnosisProblem& problem, const DiagnosisOptions& options = {});

/// Residual structure of `residuals` (mm) grouped as the problem groups its readings.
/// Harmonics of orders 1..max_order are fitted in a group's swept angle when it sweeps a full
/// turn, up to the last order its sampling resolves with a new content of at least
/// `min_new_content` (0.1: no order kept has its amplitude's noise inflated more than ~10x over
/// an evenly sampled turn by the lower orders; a spectrum is a description, so orders that
/// would mostly amplify the noise are left out). The orders left out, and why, are named in
/// GroupResidual::harmonics_left_out and harmonic_note.
std::vector<GroupResidual> residual_structure(const DiagnosisProblem& problem,
                                              const Eigen::VectorXd& residuals, int max_order = 8,
                                              double min_new_content = 0.1);

/// Noise estimate (um) from successive differences within each group, in time order:
/// sigma^2 = sum (r_{i+1} - r_i)^2 / (2 (n - 1)).
double estimate_noise_um(const DiagnosisProblem& problem, const Eigen::VectorXd& residuals);

}  // namespace rotacal
