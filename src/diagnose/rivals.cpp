// BIC weights of a finding against its rivals (rivals.hpp).
#include "rivals.hpp"

#include <algorithm>
#include <cmath>

namespace rotacal::diagnosis_detail {

RivalJudgement weigh_rivals(const Score& chosen, const std::vector<const Score*>& passing,
                            const std::vector<double>& bic, double tempering, double rival_correlation,
                            double min_weight) {
  struct Entry {
    const Score* s;
    double corr;
    double bic;
  };
  double chosen_bic = chosen.delta_bic;
  for (std::size_t i = 0; i < passing.size(); ++i)
    if (passing[i] == &chosen && std::isfinite(bic[i])) chosen_bic = bic[i];
  std::vector<Entry> field{{&chosen, 1.0, chosen_bic}};
  for (std::size_t i = 0; i < passing.size(); ++i) {
    const Score* s = passing[i];
    if (s == &chosen || !std::isfinite(bic[i])) continue;
    const double corr = std::abs(correlation(s->signature, chosen.signature));
    if (corr >= rival_correlation) field.push_back({s, corr, bic[i]});
  }
  // BIC weights relative to the best of the field (a rival may fit better than the chosen
  // one: the search passes over candidates that fail cross-validation or whose parameters
  // the refit cannot determine).
  double best_bic = chosen_bic;
  for (const Entry& e : field) best_bic = std::min(best_bic, e.bic);
  std::vector<double> w;
  double total = 0.0;
  for (const Entry& e : field) {
    w.push_back(std::exp(-0.5 * (e.bic - best_bic) / tempering));
    total += w.back();
  }
  for (double& x : w) x /= total;

  RivalJudgement out;
  out.weight = w[0];
  std::vector<std::size_t> order(field.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin() + 1, order.end(), [&](std::size_t a, std::size_t b) { return w[a] > w[b]; });
  // The group: the chosen candidate, then rivals by weight until min_weight is held.
  double held = w[0];
  std::vector<bool> member(field.size(), false);
  member[0] = true;
  for (std::size_t k = 1; k < order.size() && held < min_weight; ++k) {
    member[order[k]] = true;
    held += w[order[k]];
  }
  out.group.push_back(&chosen);
  for (std::size_t k = 1; k < order.size(); ++k) {
    const std::size_t i = order[k];
    Alternative a;
    a.effect = field[i].s->effect.id();
    a.weight = w[i];
    a.delta_bic = field[i].bic - chosen_bic;
    a.correlation = field[i].corr;
    a.in_group = member[i];
    out.rivals.push_back(a);
    if (member[i]) out.group.push_back(field[i].s);
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
