// SPDX-License-Identifier: BSD-3-Clause
// Which member of a finding's group the extended model holds (model_member.hpp).
#include "model_member.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <vector>

#include "rotacal/design/table_motion.hpp"

namespace rotacal::diagnosis_detail {

namespace {

std::string two(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

struct Member {
  const Score* s = nullptr;
  double weight = 0.0;
  double delta_bic = 0.0;  // BIC - the search pick's
};

// The group's members with their weights, highest first (the search's pick first among equals).
std::vector<Member> members_by_weight(const RivalJudgement& judged) {
  std::vector<Member> out;
  for (const Score* g : judged.group) {
    Member m{g, judged.weight, 0.0};
    if (g != judged.group.front()) {
      const std::string id = g->effect.id();
      for (const Alternative& a : judged.rivals)
        if (a.effect == id) m.weight = a.weight, m.delta_bic = a.delta_bic;
    }
    out.push_back(m);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Member& a, const Member& b) { return a.weight > b.weight; });
  return out;
}

// A location error's sigma in a member's refit over its sigma in the model before the finding:
// beside the member, how far the location errors the user loads are left undetermined. The
// largest ratio, with the error it is of (infinite where the refit leaves it unobservable).
struct Inflation {
  double ratio = 1.0;
  std::string name;
  double before = 0.0, after = 0.0;  // sigmas, mm (rad for an angle)
};
Inflation location_inflation(const ModelFit& before, const ModelFit& refit) {
  Inflation worst;
  for (const ParameterEstimate& b : before.parameters) {
    if (b.name.rfind("E_", 0) != 0 || !b.observable || !(b.std > 0.0)) continue;
    for (const ParameterEstimate& a : refit.parameters) {
      if (a.name != b.name) continue;
      const double r = a.observable && std::isfinite(a.std)
                           ? a.std / b.std
                           : std::numeric_limits<double>::infinity();
      if (r > worst.ratio) worst = {r, b.name, b.std, a.std};
    }
  }
  return worst;
}

// The noise treatment the round judged `e` under (the search's where it was not scored).
const NoiseTreatment& treatment_of(const SearchContext& S, const Round& R, const Effect& e) {
  for (std::size_t i = 0; i < R.scores.size(); ++i)
    if (R.scores[i].effect == e) return R.treatment_of[i];
  return S.noise;
}

}  // namespace

HeldMember hold_member(const SearchContext& S, const Round& R, const RivalJudgement& judged,
                       const ModelFit& before, const ModelFit& chosen_refit,
                       const EffectModel& before_effects) {
  const std::vector<Member> members = members_by_weight(judged);
  const Score* chosen = judged.group.front();
  const double k_sigma = S.options.min_determined_sigma;
  const auto refit_of = [&](const Score* s) -> const ModelFit& {
    if (s == chosen) return chosen_refit;
    EffectModel extended = before_effects;
    extended.effects.push_back(s->effect);
    return S.cache.fit(S.P, extended);
  };
  const auto determined = [&](const Score* s) {
    if (S.cache.not_held.count(s->effect.id())) return false;  // not so under the final noise
    return parameter_sigmas(refit_of(s), s->effect, treatment_of(S, R, s->effect)) >= k_sigma;
  };
  // A member beside which a location error the model determined becomes undetermined (the
  // demo's joint sessions: radial_motion_A_h3's order-2 terms trade off against E_Y0C, whose sigma
  // went from 0.04 um to 119 um, the value 8.6 um) holds no location errors worth loading.
  const auto ill_conditioned = [&](const Score* s) {
    const Inflation inf = location_inflation(before, refit_of(s));
    if (inf.ratio <= kMaxLocationInflation) return std::string();
    const bool angle =
        inf.name.size() > 2 && (inf.name[2] == 'A' || inf.name[2] == 'B' || inf.name[2] == 'C');
    const std::string unit = angle ? " urad" : " um";
    const double to = angle ? 1e6 : 1e3;
    return s->effect.id() + " leaves " + inf.name + " undetermined (its sigma " +
           two(inf.before * to) + unit + " before, " +
           (std::isfinite(inf.ratio) ? two(inf.after * to) + unit : std::string("unbounded")) +
           " beside it)";
  };
  const std::string rule6 = "determined to " + std::to_string(static_cast<int>(k_sigma)) + " sigma";

  HeldMember out;
  out.top = members.front().s;
  if (!S.options.hold_by_weight) {  // the search's pick, and what the weights say beside it
    out.member = chosen;
    out.refit = &chosen_refit;
    out.weight = judged.weight;
    if (judged.group.size() == 1)
      out.why = "it is named alone (weight " + two(judged.weight) + ")";
    else
      out.why =
          "it is the search's pick, the member that scored best of those that passed its "
          "tests (weight " +
          two(judged.weight) + ")" +
          (out.top == chosen ? std::string(", and the highest weight of its group")
                             : "; the weights rank " + out.top->effect.id() + " first (" +
                                   two(members.front().weight) +
                                   "), with another member the location errors differ");
    return out;
  }
  std::string skipped, unconditioned;
  const Member* top = nullptr;
  for (const Member& m : members) {
    if (determined(m.s)) {
      const std::string ill = ill_conditioned(m.s);
      if (ill.empty()) {
        top = &m;
        break;
      }
      unconditioned += (unconditioned.empty() ? "" : "; ") + ill + " (" + two(m.weight) + ")";
      continue;
    }
    skipped += (skipped.empty() ? "" : ", ") + m.s->effect.id() + " (" + two(m.weight) + ")";
    if (S.cache.not_held.count(m.s->effect.id())) skipped += " by GLS under the final noise";
  }
  const std::string passed_over_ill = unconditioned.empty()
                                          ? std::string()
                                          : "; passed over as a model member: " + unconditioned +
                                                ", whose location errors are no values to load";
  if (!top) {
    out.weight = members.front().weight;
    out.delta_bic = members.front().delta_bic;
    out.why = "no member of the group has a parameter " + rule6 +
              " once it is in the model with the location errors still determined: the result "
              "holds the baseline (the location errors alone) for this finding" +
              passed_over_ill;
    return out;
  }
  const bool alone = judged.group.size() == 1;
  std::string why = alone ? "it is named alone (weight " + two(top->weight) + ")"
                          : "it holds the highest weight of its group (" + two(top->weight) + ")";
  if (!skipped.empty())
    why += " of the members with a parameter " + rule6 + " (" + skipped +
           " weigh more, but none of their parameters is " + rule6 + " beside the model)";
  if (!unconditioned.empty())
    why += std::string(skipped.empty() ? " of the members" : ", and") +
           " beside which the location errors stay determined";

  // The simplest of equals: a member nested in the top one, as well supported (delta BIC <= 2,
  // "not worth more than a bare mention" on the Kass-Raftery scale), is what the data show; the
  // top one's extra parameters fit only the noise. Of several, the best fitting.
  double t_end = 0.0;
  for (double t : S.P.times()) t_end = std::max(t_end, t);
  const Member* nested = nullptr;
  std::string nest_why;
  for (const Member& m : members) {
    if (&m == top || m.s->effect.num_params() >= top->s->effect.num_params()) continue;
    if (m.delta_bic - top->delta_bic > 2.0) continue;
    if (nested && m.delta_bic >= nested->delta_bic) continue;
    const TableMotionOverlap o =
        table_motion_overlap(S.P.machine(), m.s->effect, top->s->effect, {-90.0, 90.0}, t_end);
    if (!o.first_within_second || !determined(m.s) || !ill_conditioned(m.s).empty()) continue;
    nested = &m;
    nest_why = m.s->effect.id() + " (" + two(m.weight) + ") is a special case of " +
               top->s->effect.id() + " with fewer parameters (" +
               std::to_string(m.s->effect.num_params()) + " against " +
               std::to_string(top->s->effect.num_params()) +
               ": every table motion of it is one of the other's, once the location errors and "
               "the set-up are taken out) and fits as well (delta BIC " +
               two(m.delta_bic - top->delta_bic) +
               " <= 2): the simpler one is held, the other's extra parameters fitting only noise";
  }
  const Member& held = nested ? *nested : *top;
  out.member = held.s;
  out.refit = &refit_of(held.s);
  out.weight = held.weight;
  out.delta_bic = held.delta_bic;
  out.why =
      (nested ? nest_why + " (" + top->s->effect.id() + ": " + why + ")" : why) + passed_over_ill;
  if (held.s != chosen && top->s != chosen)
    out.why += "; the search's pick, " + chosen->effect.id() + " (" + two(judged.weight) +
               "), scored best of those that passed its tests, but the weights rank it lower";
  return out;
}

// How many sigma from zero the best-determined single parameter of F is as the result reports it
// (F.parameters: the final fit's, time constants profiled, sigmas scaled).
double reported_sigmas(const Finding& F) {
  double best = 0.0;
  for (const ParameterEstimate& p : F.parameters)
    if (p.observable && p.std > 0.0 && std::isfinite(p.std))
      best = std::max(best, std::abs(p.value) / p.std);
  return best;
}
bool all_determined_as_reported(const DiagnosisOptions& options, const Diagnosis& D) {
  return std::all_of(D.findings.begin(), D.findings.end(), [&](const Finding& F) {
    return reported_sigmas(F) >= options.min_determined_sigma;
  });
}
// The same of every finding before the last (a warm-up whose tau the profile leaves open
// beside a drift found after it: thermal_warmup_Z then thermal_drift_Z on an AC-trt probe in
// AR(1) 0.5 noise, seed 1454 of tests/python/test_probe_diagnosis.py; dropped, the drift
// alone is determined, so it is not passed over).
bool earlier_determined_as_reported(const DiagnosisOptions& options, const Diagnosis& D) {
  return std::all_of(D.findings.begin(), D.findings.end() - 1, [&](const Finding& F) {
    return reported_sigmas(F) >= options.min_determined_sigma;
  });
}

// The last finding dropped (reported unobservable): its numbers, or an earlier finding's beside
// it, are not determined by `how`. Where the model holds what the weights say and the last is
// itself undetermined in a group with other scored members, it goes into `not_held` and the
// caller runs the search again holding the next member; not where `may_pass_over` is false (an
// earlier finding is undetermined too: beside that one, this one may be what the data show).
void drop_last_finding(const DiagnosisOptions& options, bool last_determined,
                       const std::string& how, Diagnosis& D, std::set<std::string>& not_held,
                       bool may_pass_over) {
  const std::string sigma =
      std::to_string(static_cast<int>(options.min_determined_sigma)) + " sigma";
  const Finding& last = D.findings.back();
  if (options.hold_by_weight && !last_determined && may_pass_over &&
      std::any_of(last.rivals.begin(), last.rivals.end(),
                  [](const Alternative& a) { return a.in_group && !a.aliased; }))
    not_held.insert(last.effect.id());
  D.unobservable.push_back(
      {last.effect.id(),
       last_determined
           ? "the search named it, but by " + how +
                 " an earlier finding's parameters cannot be determined beside it "
                 "(none reaches " +
                 sigma + ")"
           : "the search named it, but by " + how + " none of its parameters reaches " + sigma});
  D.findings.pop_back();
}

}  // namespace rotacal::diagnosis_detail
