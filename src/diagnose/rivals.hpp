#pragma once
// Internal to src/diagnose: how sure a finding is of its name. The chosen candidate of a search
// round is weighed against its rivals (the candidates of the round that explain the same
// signal) by their BIC weights; a finding names one cause only when that cause holds at least
// DiagnosisOptions::min_weight of the weight, otherwise it is the group the data cannot
// separate (issue 29: never a confident wrong name).

#include <vector>

#include "rotacal/core/noise_model.hpp"
#include "scoring.hpp"

namespace rotacal::diagnosis_detail {

/// The chosen candidate's standing among its rivals.
struct RivalJudgement {
  double weight = 1.0;                 ///< the chosen candidate's posterior weight
  std::vector<Alternative> rivals;     ///< best first; in_group marks the group members
  std::vector<const Score*> group;     ///< the chosen first, then the other members
};

/// Weigh `chosen` against the other scores of `passing` (every candidate of the round that
/// passed the F-test and BIC). A rival is a passing candidate whose fitted signature correlates
/// with the chosen one's by at least `rival_correlation` (in absolute value): it explains the
/// same part of the residual. Weights are BIC weights, w_i proportional to exp(-BIC_i / 2),
/// over the chosen candidate and its rivals. The group is the smallest set of them, best
/// first, whose weights add up to `min_weight`; it holds the chosen candidate alone when that
/// one's weight reaches `min_weight`.
/// `bic[i]`: the delta BIC of passing[i] under the noise model the field is weighed with (one
/// for all of them; +inf: not visible under it, not a rival). `tempering` (>= 1) divides the
/// BIC differences before they become weights (evidence_tempering).
RivalJudgement weigh_rivals(const Score& chosen, const std::vector<const Score*>& passing,
                            const std::vector<double>& bic, double tempering, double rival_correlation,
                            double min_weight);

/// How much the evidence between two candidates can be overstated by the noise model itself.
/// The slow signatures that tell effects apart (harmonics over a test, drifts) are judged
/// against the noise's power at low frequency, S(0) ~ s_e^2 / (1 - sum phi)^2, and that rests
/// on an AR coefficient estimated from streams of a few hundred readings: one too low by its
/// standard error sqrt((1 - phi^2) / n) makes every slow signature's chi-square too large by
/// the ratio of the two S(0). The factor is that ratio at two standard errors (over the mean
/// stream length), at most 10; 1 for white noise. At rho 0.9 over tests of ~260 readings it
/// is ~4.8, at rho 0.5 ~1.5: a BIC margin that white noise would make decisive is then not.
double evidence_tempering(const NoiseModel& model);

}  // namespace rotacal::diagnosis_detail
