// SPDX-License-Identifier: BSD-3-Clause
// Residual structure per group (RMS, mean, harmonics in the swept angle, trend) and the
// successive-difference noise estimate.
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"
#include "scoring.hpp"

namespace rotacal {

using diagnosis_detail::rms_um;
using diagnosis_detail::solve_ls;

namespace diagnosis_detail {

std::string describe_structure(const std::vector<GroupResidual>& groups) {
  const GroupResidual* worst = nullptr;
  for (const GroupResidual& g : groups)
    if (!worst || g.rms_um > worst->rms_um) worst = &g;
  if (!worst) return "";
  std::ostringstream out;
  out.precision(3);
  out << "largest residual in '" << worst->group << "' (" << worst->rms_um << " um RMS";
  if (!worst->harmonic_um.empty()) {
    const auto it = std::max_element(worst->harmonic_um.begin(), worst->harmonic_um.end());
    out << "; strongest order " << (it - worst->harmonic_um.begin()) + 1 << " in "
        << worst->angle_axis << ", " << *it << " um";
  }
  out << "; trend " << worst->trend_um_per_s << " um/s)";
  return out.str();
}

}  // namespace diagnosis_detail

double estimate_noise_um(const DiagnosisProblem& P, const Eigen::VectorXd& r) {
  const auto& g = P.groups();
  const auto& t = P.times();
  if (static_cast<std::size_t>(r.size()) != g.size())
    throw InvalidArgument("estimate_noise_um: " + std::to_string(r.size()) +
                          " residuals given for " + std::to_string(g.size()) + " readings");
  std::map<std::string, std::vector<std::size_t>> by_group;
  for (std::size_t i = 0; i < g.size(); ++i) by_group[g[i]].push_back(i);
  double ss = 0.0;
  std::size_t n = 0;
  for (auto& kv : by_group) {
    auto& idx = kv.second;
    std::stable_sort(idx.begin(), idx.end(),
                     [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
    for (std::size_t k = 1; k < idx.size(); ++k) {
      const double d =
          r[static_cast<Eigen::Index>(idx[k])] - r[static_cast<Eigen::Index>(idx[k - 1])];
      ss += d * d;
      ++n;
    }
  }
  if (n == 0)
    throw InvalidArgument("estimate_noise_um: no group has two readings (given " +
                          std::to_string(r.size()) + " residuals in " +
                          std::to_string(by_group.size()) + " groups)");
  return std::sqrt(ss / (2.0 * static_cast<double>(n))) * 1e3;
}

std::vector<GroupResidual> residual_structure(const DiagnosisProblem& P, const Eigen::VectorXd& r,
                                              int max_order, double min_new_content) {
  const auto& g = P.groups();
  const auto& t = P.times();
  const auto& a = P.angles();
  std::vector<std::string> order;
  for (const std::string& s : g)
    if (std::find(order.begin(), order.end(), s) == order.end()) order.push_back(s);
  std::vector<GroupResidual> out;
  const char tilt = tilt_axis_letter(P.machine());
  for (const std::string& name : order) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < g.size(); ++i)
      if (g[i] == name) idx.push_back(i);
    GroupResidual G;
    G.group = name;
    G.n = idx.size();
    double lo_t = 1e300, hi_t = -1e300, lo_r = 1e300, hi_r = -1e300;
    Eigen::VectorXd y(static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) {
      y[static_cast<Eigen::Index>(k)] = r[static_cast<Eigen::Index>(idx[k])];
      lo_t = std::min(lo_t, a[idx[k]].tilt), hi_t = std::max(hi_t, a[idx[k]].tilt);
      lo_r = std::min(lo_r, a[idx[k]].rot), hi_r = std::max(hi_r, a[idx[k]].rot);
    }
    G.rms_um = rms_um(y);
    G.mean_um = y.mean() * 1e3;
    // Trend against time.
    Eigen::MatrixXd T(y.size(), 2);
    for (Eigen::Index k = 0; k < y.size(); ++k)
      T(k, 0) = 1.0, T(k, 1) = t[idx[static_cast<std::size_t>(k)]];
    if (y.size() >= 3) G.trend_um_per_s = solve_ls(T, y)[1] * 1e3;
    // Harmonics in the swept angle: only over a (nearly) full turn. On a partial arc the
    // cos/sin of different orders are nearly collinear and the "spectrum" means nothing.
    const double span_t = hi_t - lo_t, span_r = hi_r - lo_r;
    const bool use_rot = span_r >= span_t;
    if (std::max(span_t, span_r) > 0.0) G.angle_axis = use_rot ? 'C' : tilt;
    // Only the orders the group's angular sampling resolves are fitted: beyond them the design
    // is rank-deficient (C every 30 deg: order 6 has a vanishing sine, 7 and 8 take the values
    // of 5 and 4), and a fit would return rounding noise divided by ~1e-15 (1e14 um and more).
    const double span = std::max(span_t, span_r);
    if (span >= 330.0 * M_PI / 180.0 && y.size() >= 20 && max_order > 0) {
      std::vector<double> th(idx.size());
      for (std::size_t k = 0; k < idx.size(); ++k) th[k] = use_rot ? a[idx[k]].rot : a[idx[k]].tilt;
      const HarmonicResolution res =
          resolve_harmonics(th, G.angle_axis, max_order, min_new_content);
      const int orders = res.resolved;
      if (orders > 0) {
        Eigen::MatrixXd H(y.size(), 1 + 2 * orders);
        for (Eigen::Index k = 0; k < y.size(); ++k) {
          H(k, 0) = 1.0;
          for (int o = 1; o <= orders; ++o) {
            H(k, 2 * o - 1) = std::cos(o * th[static_cast<std::size_t>(k)]);
            H(k, 2 * o) = std::sin(o * th[static_cast<std::size_t>(k)]);
          }
        }
        const Eigen::VectorXd c = solve_ls(H, y);
        for (int o = 1; o <= orders; ++o)
          G.harmonic_um.push_back(std::hypot(c[2 * o - 1], c[2 * o]) * 1e3);
      }
      if (orders < max_order) {
        for (int o = orders + 1; o <= max_order; ++o) G.harmonics_left_out.push_back(o);
        std::ostringstream note;
        note << (orders + 1 == max_order ? "order " : "orders ") << orders + 1;
        if (orders + 1 < max_order) note << "-" << max_order;
        note << " in " << G.angle_axis << " left out: " << res.why_not(orders + 1);
        G.harmonic_note = note.str();
      }
    } else if (G.angle_axis && max_order > 0) {
      std::ostringstream note;
      note.precision(3);
      note << "no harmonics: ";
      if (y.size() < 20)
        note << "only " << y.size() << " readings";
      else
        note << G.angle_axis << " sweeps " << span * 180.0 / M_PI << " deg, not a full turn";
      G.harmonic_note = note.str();
    }
    out.push_back(G);
  }
  return out;
}

}  // namespace rotacal

namespace rotacal::diagnosis_detail {

namespace {
// Rows of `group`, and the coordinate it sweeps (angle in rad with its axis, else time).
std::vector<std::size_t> rows_of(const DiagnosisProblem& P, const std::string& group) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < P.groups().size(); ++i)
    if (P.groups()[i] == group) idx.push_back(i);
  return idx;
}
std::vector<double> swept(const DiagnosisProblem& P, const std::vector<std::size_t>& idx,
                          char* axis) {
  double lo_t = 1e300, hi_t = -1e300, lo_r = 1e300, hi_r = -1e300;
  for (std::size_t i : idx) {
    const RotaryAngles<double>& a = P.angles()[i];
    lo_t = std::min(lo_t, a.tilt), hi_t = std::max(hi_t, a.tilt);
    lo_r = std::min(lo_r, a.rot), hi_r = std::max(hi_r, a.rot);
  }
  std::vector<double> x;
  const bool rot = hi_r - lo_r >= hi_t - lo_t;
  if (idx.empty() || std::max(hi_r - lo_r, hi_t - lo_t) <= 1e-9) {
    *axis = 0;
    for (std::size_t i : idx) x.push_back(P.times()[i]);
  } else {
    *axis = rot ? 'C' : tilt_axis_letter(P.machine());
    for (std::size_t i : idx) x.push_back(rot ? P.angles()[i].rot : P.angles()[i].tilt);
  }
  return x;
}
}  // namespace

Location locate(const DiagnosisProblem& P, const Eigen::VectorXd& r, const std::string& group) {
  Location L;
  const std::vector<std::size_t> idx = rows_of(P, group);
  const std::vector<double> x = swept(P, idx, &L.axis);
  if (x.empty()) return L;
  const double lo = *std::min_element(x.begin(), x.end()),
               hi = *std::max_element(x.begin(), x.end());
  constexpr int kBins = 12;
  std::vector<double> sum(kBins, 0.0), cnt(kBins, 0.0);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const int b =
        hi > lo ? std::min(kBins - 1, static_cast<int>((x[k] - lo) / (hi - lo) * kBins)) : 0;
    sum[static_cast<std::size_t>(b)] += r[static_cast<Eigen::Index>(idx[k])];
    cnt[static_cast<std::size_t>(b)] += 1.0;
  }
  std::vector<double> mean(kBins, 0.0);
  int peak = 0;
  for (int b = 0; b < kBins; ++b) {
    mean[static_cast<std::size_t>(b)] =
        cnt[static_cast<std::size_t>(b)] > 0
            ? sum[static_cast<std::size_t>(b)] / cnt[static_cast<std::size_t>(b)]
            : 0.0;
    if (std::abs(mean[static_cast<std::size_t>(b)]) >
        std::abs(mean[static_cast<std::size_t>(peak)]))
      peak = b;
  }
  const double half = 0.5 * std::abs(mean[static_cast<std::size_t>(peak)]);
  int first = peak, last = peak;
  while (first > 0 && std::abs(mean[static_cast<std::size_t>(first - 1)]) >= half &&
         mean[static_cast<std::size_t>(first - 1)] * mean[static_cast<std::size_t>(peak)] > 0)
    --first;
  while (last + 1 < kBins && std::abs(mean[static_cast<std::size_t>(last + 1)]) >= half &&
         mean[static_cast<std::size_t>(last + 1)] * mean[static_cast<std::size_t>(peak)] > 0)
    ++last;
  const double scale = L.axis ? 180.0 / M_PI : 1.0, w = (hi - lo) / kBins;
  L.from = (lo + first * w) * scale;
  L.to = (lo + (last + 1) * w) * scale;
  L.peak_um = mean[static_cast<std::size_t>(peak)] * 1e3;
  return L;
}

StructureTest structure_test(
    const DiagnosisProblem& P, const Eigen::VectorXd& r_mm, const Eigen::MatrixXd& Jfree,
    int num_free,
    const std::function<Whiten(const std::string&, const Eigen::MatrixXd&)>& whitener_for) {
  std::vector<std::string> order;
  for (const std::string& s : P.groups())
    if (std::find(order.begin(), order.end(), s) == order.end()) order.push_back(s);
  StructureTest out;
  double best = 1.0;
  const double n = static_cast<double>(r_mm.size());
  for (const std::string& group : order) {
    const std::vector<std::size_t> idx = rows_of(P, group);
    if (idx.size() < 20) continue;
    char axis = 0;
    const std::vector<double> x = swept(P, idx, &axis);
    const double lo = *std::min_element(x.begin(), x.end()),
                 hi = *std::max_element(x.begin(), x.end());
    if (!(hi > lo)) continue;
    std::vector<std::function<double(double)>> f;
    int orders = 0;
    if (axis && hi - lo >= 330.0 * M_PI / 180.0) {
      orders = resolve_harmonics(x, axis, 8, 0.1).resolved;
      for (int o = 1; o <= orders; ++o) {
        f.push_back([o](double th) { return std::cos(o * th); });
        f.push_back([o](double th) { return std::sin(o * th); });
      }
    } else {
      for (int d = 1; d <= 4; ++d)
        f.push_back(
            [d, lo, hi](double v) { return std::pow(2.0 * (v - lo) / (hi - lo) - 1.0, d); });
    }
    if (f.empty()) continue;
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(r_mm.size(), static_cast<Eigen::Index>(f.size()));
    for (std::size_t k = 0; k < idx.size(); ++k)
      for (std::size_t j = 0; j < f.size(); ++j)
        G(static_cast<Eigen::Index>(idx[k]), static_cast<Eigen::Index>(j)) = f[j](x[k]);
    const Whiten whiten = whitener_for(group, G);
    const Eigen::VectorXd r_w = whiten(r_mm);
    // The model's columns are full rank here (free columns of a fit): CholeskyQR2, which falls
    // back to the rank-revealing QR where they are not.
    // The test columns after that projection are full rank in most groups too; where they are
    // near rank-deficient (a harmonic the model's columns already hold) CholeskyQR2 hands the
    // rank decision to the rank-revealing QR. Its Householder QR of every group's columns was
    // most of this test's time.
    const Eigen::MatrixXd Gp = project_out(orthonormal_basis_full_rank(whiten(Jfree)), whiten(G));
    const Eigen::MatrixXd B = orthonormal_basis_full_rank(Gp);
    const auto q = static_cast<double>(B.cols());
    if (q == 0) continue;
    const Eigen::VectorXd fitted = B * (B.transpose() * r_w);
    const double rss0 = r_w.squaredNorm(), rss1 = std::max((r_w - fitted).squaredNorm(), 1e-300);
    const double dof = n - num_free - q;
    if (dof <= 0) continue;
    const double F = ((rss0 - rss1) / q) / (rss1 / dof);
    const double p = stats::f_sf(std::max(F, 0.0), q, dof);
    if (p < best) best = p, out.group = group;
  }
  out.p_value = std::min(1.0, best * static_cast<double>(order.size()));
  return out;
}

}  // namespace rotacal::diagnosis_detail

namespace rotacal {

AngleTable angle_table(const DiagnosisProblem& P, const Eigen::VectorXd& r,
                       const std::string& group, const NoiseModel& noise, double noise_um,
                       int cv_blocks) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < P.groups().size(); ++i)
    if (P.groups()[i] == group) idx.push_back(i);
  if (idx.empty()) throw InvalidArgument("angle_table: no group '" + group + "' in the session");
  AngleTable T;
  T.group = group;
  std::vector<double> x;
  {
    double lo_t = 1e300, hi_t = -1e300, lo_r = 1e300, hi_r = -1e300;
    for (std::size_t i : idx) {
      lo_t = std::min(lo_t, P.angles()[i].tilt), hi_t = std::max(hi_t, P.angles()[i].tilt);
      lo_r = std::min(lo_r, P.angles()[i].rot), hi_r = std::max(hi_r, P.angles()[i].rot);
    }
    if (std::max(hi_t - lo_t, hi_r - lo_r) <= 1e-9)
      throw InvalidArgument("angle_table: group '" + group + "' sweeps no rotary angle");
    const bool rot = hi_r - lo_r >= hi_t - lo_t;
    T.axis = rot ? 'C' : tilt_axis_letter(P.machine());
    for (std::size_t i : idx)
      x.push_back((rot ? P.angles()[i].rot : P.angles()[i].tilt) * 180.0 / M_PI);
  }
  // Bins: the distinct commanded angles (within 0.05 deg) if there are at most 72, else 36
  // equal bins over the span.
  std::vector<double> sorted(x);
  std::sort(sorted.begin(), sorted.end());
  std::vector<double> centres;
  for (double a : sorted)
    if (centres.empty() || a - centres.back() > 0.05) centres.push_back(a);
  std::vector<int> bin(x.size());
  if (centres.size() <= 72) {
    for (std::size_t k = 0; k < x.size(); ++k)
      bin[k] = static_cast<int>(std::min_element(centres.begin(), centres.end(),
                                                 [&](double a, double b) {
                                                   return std::abs(a - x[k]) < std::abs(b - x[k]);
                                                 }) -
                                centres.begin());
  } else {
    const double lo = sorted.front(), hi = sorted.back(), w = (hi - lo) / 36.0;
    centres.clear();
    for (int b = 0; b < 36; ++b) centres.push_back(lo + (b + 0.5) * w);
    for (std::size_t k = 0; k < x.size(); ++k)
      bin[k] = std::min(35, static_cast<int>((x[k] - lo) / w));
  }
  const std::size_t B = centres.size();
  std::vector<double> sum(B, 0.0);
  std::vector<int> cnt(B, 0);
  for (std::size_t k = 0; k < idx.size(); ++k)
    sum[static_cast<std::size_t>(bin[k])] += r[static_cast<Eigen::Index>(idx[k])],
        ++cnt[static_cast<std::size_t>(bin[k])];
  // Noise per reading and its correlation within the group (largest over its streams).
  double tau = 1.0;
  for (const NoiseStream& st : noise.streams)
    if (st.group == group) tau = std::max(tau, st.correlation_samples);
  const double sigma = noise.white() || noise.sigma_um <= 0.0 ? noise_um : noise.sigma_um;
  Eigen::VectorXd after = r;
  int used = 0;
  for (std::size_t b = 0; b < B; ++b) {
    if (cnt[b] == 0) continue;
    ++used;
    T.angle_deg.push_back(centres[b]);
    T.value_um.push_back(sum[b] / cnt[b] * 1e3);
    T.std_um.push_back(sigma * std::sqrt(std::min(tau, static_cast<double>(cnt[b])) / cnt[b]));
    T.count.push_back(cnt[b]);
  }
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const auto b = static_cast<std::size_t>(bin[k]);
    after[static_cast<Eigen::Index>(idx[k])] -= sum[b] / cnt[b];
  }
  const double n = static_cast<double>(r.size());
  const double n_eff =
      noise.white() ? n : std::max(noise.effective_samples, static_cast<double>(used) + 2.0);
  const double rss0 = std::max(r.squaredNorm(), 1e-300),
               rss1 = std::max(after.squaredNorm(), 1e-300);
  T.gain.rms_before_um = std::sqrt(rss0 / n) * 1e3;
  T.gain.rms_after_um = std::sqrt(rss1 / n) * 1e3;
  // The likelihood scale of correlated residuals is their effective number of samples.
  T.gain.delta_bic = n_eff * std::log(rss1 / rss0) + used * std::log(n_eff);
  const double dof = n_eff - used;
  const double F = ((rss0 - rss1) / used) / (rss1 / dof);
  T.gain.f_pvalue = dof > 0 ? stats::f_sf(std::max(F, 0.0), used, dof) : 1.0;
  // Cross-validation: contiguous blocks of the group in time order; each block predicted by
  // the bin means of the other blocks.
  std::vector<std::size_t> order(idx.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return P.times()[idx[a]] < P.times()[idx[b]];
  });
  const int K = std::clamp(static_cast<int>(static_cast<double>(idx.size()) / tau), 2,
                           std::max(2, cv_blocks));
  std::vector<int> fold(idx.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    fold[order[k]] = static_cast<int>(k * static_cast<std::size_t>(K) / order.size());
  double ss_before = 0.0, ss_after = 0.0;
  for (int f = 0; f < K; ++f) {
    std::vector<double> s(B, 0.0);
    std::vector<int> c(B, 0);
    for (std::size_t k = 0; k < idx.size(); ++k)
      if (fold[k] != f)
        s[static_cast<std::size_t>(bin[k])] += r[static_cast<Eigen::Index>(idx[k])],
            ++c[static_cast<std::size_t>(bin[k])];
    for (std::size_t k = 0; k < idx.size(); ++k) {
      if (fold[k] != f) continue;
      const double y = r[static_cast<Eigen::Index>(idx[k])];
      const auto b = static_cast<std::size_t>(bin[k]);
      const double pred = c[b] ? s[b] / c[b] : 0.0;
      ss_before += y * y;
      ss_after += (y - pred) * (y - pred);
    }
  }
  T.gain.cv_rms_before_um = std::sqrt(ss_before / static_cast<double>(idx.size())) * 1e3;
  T.gain.cv_rms_after_um = std::sqrt(ss_after / static_cast<double>(idx.size())) * 1e3;
  return T;
}

}  // namespace rotacal
