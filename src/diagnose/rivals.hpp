// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: how sure a finding is of its name. The chosen candidate of a search
// round is weighed against its rivals (the candidates of the round that explain the same
// signal) by their posterior weights; a finding names one cause only when that cause holds at
// least DiagnosisOptions::min_weight of the weight, otherwise it is the group the data cannot
// separate (issue 29: never a confident wrong name).

#include <vector>

#include "rotacal/core/noise_model.hpp"
#include "scoring.hpp"

namespace rotacal::diagnosis_detail {

/// The chosen candidate's standing among its rivals.
struct RivalJudgement {
  double weight = 1.0;              ///< the chosen candidate's posterior weight
  std::vector<Alternative> rivals;  ///< best first; in_group marks the group members
  std::vector<const Score*> group;  ///< the chosen first, then the other members
};

/// Which of `field` pass the BIC threshold alone but not beside `chosen` (the same inputs): the two
/// compete for one signal even where their fitted signatures correlate little. A 3x
/// tilt_motion_C_h4 on the AC-trt ballbar in 1/f-like noise scored -21.6 against
/// radial_motion_C_h4's -23.2, their signatures correlated by 0.44 (under rival_correlation), and
/// beside the radial motion the tilt scored +0.4: the radial motion was named alone at weight 1.00
/// (bench/diagnosis_confusion.py
/// --noise pink --seed 251). An effect of its own beside the chosen one keeps its evidence (a
/// thermal drift beside a straightness, -11.8 alone, -12.4 beside it) and stays out.
/// Each is judged on `in` (the model before the finding, under the noise model the field is
/// weighed with) by the chosen one's and its own whitened columns (Score::A): its delta BIC beside
/// the chosen one against min_delta_bic. Only candidates whose signature correlates with the chosen
/// one's by less than rival_correlation are judged (the others are rivals anyway).
std::vector<bool> explained_away(const ScoringInputs& in, const Score& chosen,
                                 const std::vector<const Score*>& field, double min_delta_bic,
                                 double rival_correlation);

/// Weigh `chosen` against the other scores of `field` (every observable candidate of the round,
/// whether it passed the round's tests or not: a rival that fits as well but failed the F-test
/// or the BIC threshold is no less a rival). A rival is a candidate of the field whose fitted
/// signature correlates with the chosen one's by at least `rival_correlation` (in absolute
/// value): it explains the same part of the residual.
///
/// The weight of each is its posterior weight, w_i proportional to exp(-IC_i / 2), over the
/// chosen candidate and its rivals, with IC = chi2 + c k (k visible parameters). The Occam
/// term c rests on a prior on the effect's size that the data do not give: BIC's c = ln n is
/// the unit-information prior, a size sqrt(n) times the effect's standard error, far above the
/// effects the diagnosis sees near its detection limit, for which AIC's c = 2 (the Occam
/// factor of a prior a few standard errors wide) is closer. A cause is only as sure as the
/// data make it whatever that prior, so the chosen candidate's weight is the smaller of the
/// two (1 / w_chosen = sum_i exp(-(IC_i - IC_chosen) / 2) is convex in c, so its largest value
/// over [2, ln n] is at an end), and the
/// weights of the field are those of that end. Without this, a rival with one more parameter
/// that fits the readings as well (a straightness against an axial harmonic, a tilt harmonic
/// against coning) was outweighed 40:1 by the parameter count alone: the refsim confusion bench
/// named the simpler wrong cause in 4-6 % of white-noise sessions at 1x the half-detection
/// amplitude.
///
/// The group is the smallest set of them, best first, whose weights add up to `min_weight`,
/// and any further rival that a member of that set cannot be told apart from: the member's
/// weight against the rival alone below min_weight (DiagnosisOptions::min_weight) at either
/// end of the Occam term. So no rival that outweighs a member is left out, nor one that fits
/// as well as a member with more parameters (on one probe sphere a radial motion of C fits
/// exactly as its angular positioning does; at BIC's term alone the group [tilt, angular
/// positioning] left the true radial motion out). It holds the chosen candidate alone when
/// that one's weight reaches `min_weight` (every rival then holds less than 1 - min_weight at
/// both ends).
/// `bic[i]`: the delta BIC of field[i] under the noise model the field is weighed with (one for
/// all of them; +inf: not visible under it, not a rival); `n`: the readings (BIC's ln n).
/// `tempering` (>= 1) divides the differences before they become weights (evidence_tempering).
/// `explained_away[i]`: field[i] passed the detection threshold alone but not beside the chosen
/// candidate (explained_away); such a candidate is a rival whatever its
/// signature's correlation: the data support one of the two, not both.
RivalJudgement weigh_rivals(const Score& chosen, const std::vector<const Score*>& field,
                            const std::vector<double>& bic, double n, double tempering,
                            double rival_correlation, double min_weight,
                            const std::vector<bool>& explained_away = {});

/// The chosen candidate's standing under two noise models the data cannot choose between (the
/// same candidate chosen in both): the smaller weight, with the rivals of that judgement, and
/// the union of the two groups (the other's members marked in_group). A name is only as sure
/// as the looser model lets it be, and a rival that only the tighter one cannot tell apart
/// (their signatures correlate at its middle frequencies) is no less a rival.
RivalJudgement worse_of(const RivalJudgement& a, const RivalJudgement& b);

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
