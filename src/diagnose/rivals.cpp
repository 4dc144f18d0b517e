// SPDX-License-Identifier: BSD-3-Clause
// Posterior weights of a finding against its rivals (rivals.hpp).
#include "rivals.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace rotacal::diagnosis_detail {

namespace {

// Normalised weights exp(-(IC_i - min IC) / (2 tempering)), IC_i = bic_i - k_i (ln n - c): the
// Occam term per parameter c instead of BIC's ln n.
std::vector<double> weights_at(const std::vector<double>& bic, const std::vector<int>& k, double n,
                               double c, double tempering) {
  std::vector<double> ic(bic.size());
  for (std::size_t i = 0; i < bic.size(); ++i) ic[i] = bic[i] - k[i] * (std::log(n) - c);
  const double best = *std::min_element(ic.begin(), ic.end());
  std::vector<double> w(ic.size());
  double total = 0.0;
  for (std::size_t i = 0; i < ic.size(); ++i)
    total += (w[i] = std::exp(-0.5 * (ic[i] - best) / tempering));
  for (double& x : w) x /= total;
  return w;
}

}  // namespace

std::vector<bool> explained_away(const ScoringInputs& in, const Score& chosen,
                                 const std::vector<const Score*>& field, double min_delta_bic,
                                 double rival_correlation) {
  std::vector<bool> out(field.size(), false);
  if (!chosen.observable || chosen.A.cols() == 0) return out;
  const Eigen::MatrixXd Qc = orthonormal_basis(chosen.A);
  const Eigen::VectorXd e = in.r_w - Qc * (Qc.transpose() * in.r_w);  // what the chosen one leaves
  const double n = static_cast<double>(in.r_w.size()), rss_c = e.squaredNorm();
  for (std::size_t i = 0; i < field.size(); ++i) {
    const Score& s = *field[i];
    if (&s == &chosen || !s.observable || s.A.cols() == 0 || !(s.delta_bic < min_delta_bic) ||
        std::abs(correlation(s.signature, chosen.signature)) >=
            rival_correlation)  // a rival anyway
      continue;
    const Eigen::MatrixXd Qs = orthonormal_basis(s.A - Qc * (Qc.transpose() * s.A));
    const double drop = std::min((Qs.transpose() * e).squaredNorm(), rss_c * (1.0 - 1e-12));
    out[i] = n * std::log((rss_c - drop) / rss_c) + s.k * std::log(n) >= min_delta_bic;
  }
  return out;
}

RivalJudgement weigh_rivals(const Score& chosen, const std::vector<const Score*>& field,
                            const std::vector<double>& bic, double n, double tempering,
                            double rival_correlation, double min_weight,
                            const std::vector<bool>& explained_away) {
  std::vector<const Score*> who{&chosen};
  std::vector<double> corr{1.0};
  double chosen_bic = chosen.delta_bic;
  for (std::size_t i = 0; i < field.size(); ++i)
    if (field[i] == &chosen && std::isfinite(bic[i])) chosen_bic = bic[i];
  std::vector<double> ic_bic{chosen_bic};
  std::vector<int> k{chosen.k};
  for (std::size_t i = 0; i < field.size(); ++i) {
    const Score* s = field[i];
    if (s == &chosen || !std::isfinite(bic[i])) continue;
    const double c = std::abs(correlation(s->signature, chosen.signature));
    if (c < rival_correlation && !(i < explained_away.size() && explained_away[i])) continue;
    who.push_back(s), corr.push_back(c), ic_bic.push_back(bic[i]), k.push_back(s->k);
  }
  // Weights relative to the best of the field (a rival may fit better than the chosen one: the
  // search passes over candidates that fail cross-validation or whose parameters the refit
  // cannot determine), at both ends of the Occam term; the chosen one stands by the worse.
  const std::vector<double> w_bic = weights_at(ic_bic, k, n, std::log(n), tempering);
  const std::vector<double> w_aic = weights_at(ic_bic, k, n, 2.0, tempering);
  const std::vector<double>& w = w_aic[0] < w_bic[0] ? w_aic : w_bic;

  RivalJudgement out;
  out.weight = w[0];
  std::vector<std::size_t> order(who.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin() + 1, order.end(),
                   [&](std::size_t a, std::size_t b) { return w[a] > w[b]; });
  // The group: the chosen candidate, then rivals by weight until min_weight is held; then every
  // rival that some member cannot be told apart from (that member's weight against it alone
  // below min_weight) at either end of the Occam term. A rival just outside the weight that
  // completes min_weight is no less a candidate than the last one inside it, one that outweighs
  // a member (the chosen one can hold little weight: the search passes over better-fitting
  // candidates that fail cross-validation) is more of one, and one that fits as well as a
  // member with more parameters is set apart from it only by a prior on its size, which the
  // chosen candidate's own weight does not rest on either.
  double held = w[0];
  std::vector<bool> member(who.size(), false);
  member[0] = true;
  for (std::size_t j = 1; j < order.size() && held < min_weight; ++j) {
    member[order[j]] = true;
    held += w[order[j]];
  }
  const double margin = (1.0 - min_weight) / min_weight;  // w_m / (w_m + w_i) < min_weight
  std::vector<std::size_t> members;
  for (std::size_t i = 0; i < who.size(); ++i)
    if (member[i]) members.push_back(i);
  for (std::size_t i = 0; i < who.size(); ++i)
    for (std::size_t m : members)
      if (!member[i] && (w_bic[i] > margin * w_bic[m] || w_aic[i] > margin * w_aic[m]))
        member[i] = true;
  out.group.push_back(&chosen);
  for (std::size_t j = 1; j < order.size(); ++j) {
    const std::size_t i = order[j];
    Alternative a;
    a.effect = who[i]->effect.id();
    a.weight = w[i];
    a.delta_bic = ic_bic[i] - chosen_bic;
    a.correlation = corr[i];
    a.in_group = member[i];
    out.rivals.push_back(a);
    if (member[i]) out.group.push_back(who[i]);
  }
  return out;
}

RivalJudgement worse_of(const RivalJudgement& a, const RivalJudgement& b) {
  const bool a_worse = a.weight <= b.weight;
  RivalJudgement out = a_worse ? a : b;
  const RivalJudgement& other = a_worse ? b : a;
  for (const Score* g : other.group) {
    const auto same = [&](const Score* h) { return h->effect == g->effect; };
    if (std::any_of(out.group.begin(), out.group.end(), same)) continue;
    out.group.push_back(g);
    const std::string id = g->effect.id();
    const auto listed = [&](const Alternative& x) { return x.effect == id; };
    auto it = std::find_if(out.rivals.begin(), out.rivals.end(), listed);
    if (it == out.rivals.end())
      it = out.rivals.insert(out.rivals.end(),
                             *std::find_if(other.rivals.begin(), other.rivals.end(), listed));
    it->in_group = true;
  }
  return out;
}

double evidence_tempering(const NoiseModel& model) {
  double phi = 0.0, n = 0.0;
  int streams = 0;
  for (const NoiseStream& st : model.streams) {
    if (st.ar.empty()) continue;
    double sum = 0.0;
    for (double a : st.ar) sum += a;
    phi += sum;
    n += static_cast<double>(st.rows.size());
    ++streams;
  }
  if (streams == 0) return 1.0;
  phi /= streams;
  n /= streams;
  if (!(phi > 0.0) || !(n > 1.0)) return 1.0;
  phi = std::min(phi, 0.999);
  const double se = std::sqrt(std::max(1.0 - phi * phi, 0.0) / n);
  const double phi_hi = std::min(phi + 2.0 * se, 0.999);
  const double ratio = (1.0 - phi) / (1.0 - phi_hi);
  return std::min(10.0, std::max(1.0, ratio * ratio));
}

}  // namespace rotacal::diagnosis_detail
