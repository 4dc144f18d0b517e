#pragma once
/// \file
/// Diagnosis: show what the fitted model gets wrong, name the physical cause from the
/// catalogue (../shared/spec/effects.md), extend the model with it, measure the gain.
///
/// The engine is independent of the instrument. A `DiagnosisProblem` (ballbar_diagnosis.hpp,
/// R-test later) supplies the nonlinear fit of baseline + effects and each candidate's
/// Jacobian; the engine does the statistics:
///  1. baseline fit; adequacy by chi-square against the noise (declared in the file, or
///     estimated from successive differences, which smooth systematic errors barely affect);
///  2. residual structure per group (test or nest): RMS, harmonics in the rotary angle, trend;
///  3. every candidate scored by a linearised refit from the current model (the model is
///     linear in um/urad-sized parameters to far below the noise): delta BIC, F-test with a
///     Bonferroni correction over the candidates, and blocked cross-validation (contiguous
///     blocks of each group left out in turn, so the extension must predict unseen angles);
///  4. the best significant candidate is added, the model refitted (nonlinear), and 3 repeats
///     until nothing significant is left;
///  5. candidates the data cannot see are reported unobservable; candidates that explain the
///     data as well as the chosen one are reported ambiguous; significant structure that is
///     left is reported unexplained with its signature.

#include <optional>
#include <string>
#include <vector>

#include "rotacal/ballbar/identify.hpp"
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
};

/// What the engine needs from an instrument.
class DiagnosisProblem {
 public:
  virtual ~DiagnosisProblem() = default;
  virtual MachineType machine() const = 0;
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
  /// d model / d (parameters of `candidate`) at `at`, one row per reading.
  virtual Eigen::MatrixXd candidate_jacobian(const ModelFit& at, const Effect& candidate) const = 0;
  /// The group names of a complete standard test for this machine and instrument, and the
  /// candidate Jacobian on it (used to name the test that separates two ambiguous
  /// candidates). Empty if the instrument has no standard test.
  virtual std::vector<std::string> reference_groups() const { return {}; }
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
  double ambiguity_delta_bic = 10.0;  ///< candidates within this BIC of the best ...
  double ambiguity_correlation = 0.95;  ///< ... whose fitted signatures correlate this well
  std::vector<std::string> only;  ///< restrict candidates to these ids (empty: all)
  /// A candidate is visible when moving its parameters by plausible sizes (1 mm, 1 mrad,
  /// 1 um/s, 1e-3 for ratios) beyond what the model absorbs changes chi-square by at least
  /// this much (25: a 5-sigma change); others are reported unobservable.
  double min_visible_chi2 = 25.0;
};

/// Residual structure of one group.
struct GroupResidual {
  std::string group;
  std::size_t n = 0;
  double rms_um = 0.0;
  double mean_um = 0.0;
  char angle_axis = 0;                 ///< the rotary axis that varies in the group (0: none)
  std::vector<double> harmonic_um;     ///< amplitude of orders 1..8 in that angle, um (only
                                       ///< when it sweeps a full turn; empty otherwise)
  double trend_um_per_s = 0.0;         ///< least-squares slope against time
};

struct Gain {
  double rms_before_um = 0.0;
  double rms_after_um = 0.0;
  double delta_bic = 0.0;
  double cv_rms_before_um = 0.0;
  double cv_rms_after_um = 0.0;
  double f_pvalue = 1.0;
};

struct Finding {
  Effect effect;
  std::string cause;
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
  double chi2_per_dof = 0.0;
  double p_value = 1.0;
  std::string signature;  ///< the strongest remaining structure, in words
};

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
    double p_value = 1.0;      ///< P(chi2 >= observed) if the baseline were adequate
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
  ModelFit baseline_fit;
  ModelFit final_fit;
  double seconds = 0.0;  ///< wall time of the diagnosis
};

/// Run the diagnosis. Throws InvalidArgument for unknown ids in options.only.
Diagnosis diagnose(const DiagnosisProblem& problem, const DiagnosisOptions& options = {});

/// Residual structure of `residuals` (mm) grouped as the problem groups its readings.
std::vector<GroupResidual> residual_structure(const DiagnosisProblem& problem,
                                              const Eigen::VectorXd& residuals);

/// Noise estimate (um) from successive differences within each group, in time order:
/// sigma^2 = sum (r_{i+1} - r_i)^2 / (2 (n - 1)).
double estimate_noise_um(const DiagnosisProblem& problem, const Eigen::VectorXd& residuals);

}  // namespace rotacal
