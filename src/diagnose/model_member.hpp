// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: which member of a finding's group the extended model holds (issue 50
// item 3). The search adds the best-scoring candidate that passes its tests, but the weights rank
// the group by the evidence at both Occam terms, and the location errors the user loads are the
// extended model's: so the model holds what the weights say, the simplest of equals, and only
// what the data determine.

#include <set>
#include <string>

#include "rivals.hpp"
#include "search.hpp"

namespace rotacal::diagnosis_detail {

/// The member the extended model holds for one finding.
struct HeldMember {
  const Score* member = nullptr;    ///< null: no member is determined, the model holds the baseline
  const Score* top = nullptr;       ///< the group's member of the highest weight
  const ModelFit* refit = nullptr;  ///< of the model before the finding + member (cache-held)
  double weight = 0.0;              ///< member's (else top's) posterior weight
  double delta_bic = 0.0;           ///< member's (else top's) BIC - the search's pick's
  std::string why;                  ///< in words, for the report
};

/// A member's refit may widen a location error's sigma by at most this factor over the model
/// before the finding (a variance inflation of 100); beyond it the member is passed over.
inline constexpr double kMaxLocationInflation = 10.0;

/// The rule: by weight, the first member of `judged.group` (its weights in `judged`) whose refit
/// from `before_effects` determines a parameter of it to DiagnosisOptions::min_determined_sigma
/// (issue 29's rule 6 as issue 50 states it for the model member: a single parameter, not only
/// a combination, so a warm-up whose d and tau trade off along a drift is not held); where a
/// member nested in it (a special case with fewer parameters: every table motion of it is one of
/// the other's, design/table_motion.hpp) is determined and within delta BIC <= 2 of it, that
/// simpler one; where no member is determined, the baseline. A member beside which a location
/// error is no longer determined (its sigma over kMaxLocationInflation times that in `before`,
/// the fit of `before_effects`) is passed over as an undetermined one is, and the reason says so.
/// `chosen_refit`: the search pick's.
HeldMember hold_member(const SearchContext& S, const Round& R, const RivalJudgement& judged,
                       const ModelFit& before, const ModelFit& chosen_refit,
                       const EffectModel& before_effects);

/// Issue 29's rule 6 on the numbers the result reports (the final fit's, time constants profiled,
/// sigmas scaled: Finding::parameters), for the final model's members (diagnosis.cpp): how many
/// sigma from zero F's best-determined single parameter is; whether every finding, or every one
/// before the last, has one at DiagnosisOptions::min_determined_sigma.
double reported_sigmas(const Finding& F);
bool all_determined_as_reported(const DiagnosisOptions& options, const Diagnosis& D);
bool earlier_determined_as_reported(const DiagnosisOptions& options, const Diagnosis& D);

/// The last finding of D dropped and reported unobservable, its numbers (or an earlier
/// finding's beside it, `last_determined`) not determined by `how`; see model_member.cpp.
void drop_last_finding(const DiagnosisOptions& options, bool last_determined,
                       const std::string& how, Diagnosis& D, std::set<std::string>& not_held,
                       bool may_pass_over = true);

}  // namespace rotacal::diagnosis_detail
