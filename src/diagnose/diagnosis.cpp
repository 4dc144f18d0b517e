#include "rotacal/diagnose/diagnosis.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include "rotacal/core/least_squares.hpp"
#include "rotacal/core/stats.hpp"

namespace rotacal {

namespace {

double rss(const Eigen::VectorXd& r) { return r.squaredNorm(); }
double rms_um(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / static_cast<double>(r.size())) * 1e3 : 0.0;
}

// Plausible magnitudes of a candidate's parameters (for observability and scaling).
Eigen::VectorXd magnitudes(const Effect& c) {
  const auto units = c.param_units();
  Eigen::VectorXd m(static_cast<Eigen::Index>(units.size()));
  for (std::size_t k = 0; k < units.size(); ++k)
    m[static_cast<Eigen::Index>(k)] = plausible_magnitude(units[k]);
  return m;
}

// Least squares y ~ X d with columns scaled to unit norm and rank-revealing QR, so that
// directions the rows cannot see get no weight instead of blowing up.
Eigen::VectorXd solve_ls(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  if (X.cols() == 0) return Eigen::VectorXd();
  Eigen::VectorXd s = X.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < s.size(); ++j)
    if (!(s[j] > 0.0)) s[j] = 1.0;
  const Eigen::MatrixXd Xs = X * s.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Xs);
  qr.setThreshold(1e-9);
  return (qr.solve(y)).cwiseQuotient(s);
}

// Orthonormal basis of span(J) (rank-revealing), computed once per model and reused for
// every candidate's projection.
Eigen::MatrixXd orthonormal_basis(const Eigen::MatrixXd& J) {
  if (J.cols() == 0) return Eigen::MatrixXd(J.rows(), 0);
  Eigen::VectorXd s = J.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < s.size(); ++j)
    if (!(s[j] > 0.0)) s[j] = 1.0;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J * s.cwiseInverse().asDiagonal());
  qr.setThreshold(1e-9);
  const Eigen::Index r = qr.rank();
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(J.rows(), r);
  return qr.householderQ() * Q;
}

// Columns of C with their component in span(Q) removed (Q orthonormal).
Eigen::MatrixXd project_out(const Eigen::MatrixXd& Q, const Eigen::MatrixXd& C) {
  return C - Q * (Q.transpose() * C);
}

// Free (non-zero) columns of a fit's Jacobian.
Eigen::MatrixXd free_columns(const Eigen::MatrixXd& J) {
  std::vector<Eigen::Index> keep;
  for (Eigen::Index j = 0; j < J.cols(); ++j)
    if (J.col(j).squaredNorm() > 0.0) keep.push_back(j);
  Eigen::MatrixXd out(J.rows(), static_cast<Eigen::Index>(keep.size()));
  for (std::size_t k = 0; k < keep.size(); ++k) out.col(static_cast<Eigen::Index>(k)) = J.col(keep[k]);
  return out;
}

// Blocked K-fold assignment: each group's readings in time order, cut into K contiguous blocks.
std::vector<int> cv_folds(const DiagnosisProblem& P, int K) {
  const auto& g = P.groups();
  const auto& t = P.times();
  std::map<std::string, std::vector<std::size_t>> by_group;
  for (std::size_t i = 0; i < g.size(); ++i) by_group[g[i]].push_back(i);
  std::vector<int> fold(g.size(), 0);
  for (auto& kv : by_group) {
    auto& idx = kv.second;
    std::stable_sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
    for (std::size_t k = 0; k < idx.size(); ++k)
      fold[idx[k]] = static_cast<int>(k * static_cast<std::size_t>(K) / idx.size());
  }
  return fold;
}

// Cross-validated RMS (um) of predicting r from columns X (linearised refit on the rest).
double cv_rms_um(const Eigen::MatrixXd& X, const Eigen::VectorXd& r, const std::vector<int>& fold,
                 int K) {
  double ss = 0.0;
  std::size_t n = 0;
  for (int k = 0; k < K; ++k) {
    std::vector<Eigen::Index> tr, te;
    for (std::size_t i = 0; i < fold.size(); ++i)
      (fold[i] == k ? te : tr).push_back(static_cast<Eigen::Index>(i));
    if (te.empty() || tr.empty()) continue;
    Eigen::MatrixXd Xt(static_cast<Eigen::Index>(tr.size()), X.cols());
    Eigen::VectorXd yt(static_cast<Eigen::Index>(tr.size()));
    for (std::size_t i = 0; i < tr.size(); ++i) {
      Xt.row(static_cast<Eigen::Index>(i)) = X.row(tr[i]);
      yt[static_cast<Eigen::Index>(i)] = r[tr[i]];
    }
    const Eigen::VectorXd d = solve_ls(Xt, yt);
    for (Eigen::Index i : te) {
      const double e = r[i] - (X.cols() ? X.row(i).dot(d) : 0.0);
      ss += e * e;
      ++n;
    }
  }
  return n ? std::sqrt(ss / static_cast<double>(n)) * 1e3 : 0.0;
}

struct Score {
  Effect effect;
  bool observable = false;
  std::string why_not;
  int k = 0;                   // observable directions
  Eigen::MatrixXd A;           // observable part of the candidate's columns, J projected out
  Eigen::MatrixXd X;           // [J, candidate columns] for cross-validation
  Eigen::VectorXd signature;   // fitted change of the model, mm
  double rss1 = 0.0;
  double delta_bic = 0.0;
  double f_pvalue = 1.0;
};

Score score(const DiagnosisProblem& P, const ModelFit& fit, const Eigen::MatrixXd& Jfree,
            const Eigen::MatrixXd& Q, const Effect& c, double sigma_mm, double min_chi2) {
  Score s;
  s.effect = c;
  const Eigen::MatrixXd Jc = P.candidate_jacobian(fit, c);
  const Eigen::VectorXd m = magnitudes(c);
  const Eigen::MatrixXd raw = Jc * m.asDiagonal() / sigma_mm;
  const Eigen::MatrixXd perp = project_out(Q, Jc) * m.asDiagonal() / sigma_mm;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(perp, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  std::vector<Eigen::Index> dirs;
  const double limit = std::sqrt(min_chi2);
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (sv[i] >= limit) dirs.push_back(i);  // plausible sizes change chi-square by >= min_chi2
  if (dirs.empty()) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd_raw(raw);
    const bool absorbed = svd_raw.singularValues().size() && svd_raw.singularValues()[0] >= limit;
    s.why_not = absorbed
                    ? "its effect on these readings is indistinguishable from the location "
                      "errors and set-up parameters already in the model"
                    : "at any plausible size it changes these readings by less than 5 sigma "
                      "in all (e.g. a motion perpendicular to the bar)";
    return s;
  }
  s.observable = true;
  s.k = static_cast<int>(dirs.size());
  Eigen::MatrixXd V(perp.cols(), s.k);
  for (int i = 0; i < s.k; ++i) V.col(i) = svd.matrixV().col(dirs[static_cast<std::size_t>(i)]);
  s.A = perp * V * sigma_mm;  // back to mm per scaled unit
  Eigen::MatrixXd Jc_obs = Jc * m.asDiagonal() * V;
  s.X.resize(Jfree.rows(), Jfree.cols() + s.k);
  s.X << Jfree, Jc_obs;
  const Eigen::VectorXd d = solve_ls(s.A, fit.residuals);
  s.signature = s.A * d;
  const double rss0 = rss(fit.residuals);
  s.rss1 = std::max(rss(fit.residuals - s.signature), 1e-300);
  const double n = static_cast<double>(fit.residuals.size());
  const double dof = n - fit.num_free - s.k;
  s.delta_bic = n * std::log(s.rss1 / rss0) + s.k * std::log(n);
  const double F = ((rss0 - s.rss1) / s.k) / (s.rss1 / dof);
  s.f_pvalue = stats::f_sf(std::max(F, 0.0), s.k, dof);
  return s;
}

double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double na = a.norm(), nb = b.norm();
  return na > 0 && nb > 0 ? a.dot(b) / (na * nb) : 0.0;
}

std::string separating_test(const DiagnosisProblem& P, const ModelFit& fit, const Score& a,
                            const Score& b, double sigma_mm) {
  if (P.reference_groups().empty())
    return "no standard test is known for this instrument; none of this session's tests "
           "separates them";
  // Fit each candidate's full parameter vector to this session's residual, then compare what
  // they predict on the standard test.
  std::vector<std::string> rows_a, rows_b;
  const Eigen::MatrixXd Ra = P.reference_jacobian(fit, a.effect, &rows_a);
  const Eigen::MatrixXd Rb = P.reference_jacobian(fit, b.effect, &rows_b);
  const Eigen::VectorXd pa = P.candidate_jacobian(fit, a.effect).jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(a.signature);
  const Eigen::VectorXd pb = P.candidate_jacobian(fit, b.effect).jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(b.signature);
  const Eigen::VectorXd diff = Ra * pa - Rb * pb;
  std::map<std::string, std::pair<double, int>> per;
  for (std::size_t i = 0; i < rows_a.size(); ++i) {
    auto& acc = per[rows_a[i]];
    acc.first += diff[static_cast<Eigen::Index>(i)] * diff[static_cast<Eigen::Index>(i)];
    acc.second += 1;
  }
  std::string best;
  double best_rms = 0.0;
  for (auto& kv : per) {
    const double r = std::sqrt(kv.second.first / kv.second.second);
    if (r > best_rms) best_rms = r, best = kv.first;
  }
  std::ostringstream out;
  out.precision(2);
  if (best.empty() || best_rms < sigma_mm)
    out << "no test of the standard single set-up separates them (their predictions differ by "
           "less than the noise there): another set-up, e.g. another pivot position, is needed";
  else
    out << "a '" << best << "' test separates them: their predictions differ there by "
        << std::fixed << best_rms * 1e3 << " um RMS";
  return out.str();
}

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
    out << "; strongest order " << (it - worst->harmonic_um.begin()) + 1 << " in " << worst->angle_axis
        << ", " << *it << " um";
  }
  out << "; trend " << worst->trend_um_per_s << " um/s)";
  return out.str();
}

}  // namespace

HarmonicResolution resolve_harmonics(const std::vector<double>& angles_rad, char axis,
                                     int max_order, double min_new_content) {
  if (max_order < 0) throw InvalidArgument("resolve_harmonics: max_order must be >= 0");
  if (!(min_new_content > 0.0 && min_new_content <= 1.0))
    throw InvalidArgument("resolve_harmonics: min_new_content must be in (0, 1]");
  HarmonicResolution R;
  R.axis = axis;
  R.max_order = max_order;
  R.min_new_content = min_new_content;
  if (angles_rad.empty()) {
    R.new_content.assign(static_cast<std::size_t>(max_order), 0.0);
    return R;
  }
  // Distinct angles on the circle: readings at the same commanded angle (or within encoder
  // jitter, 0.05 deg) count once, with their number as weight.
  const double turn = 2.0 * M_PI, same = 0.05 * M_PI / 180.0;
  std::vector<double> a;
  a.reserve(angles_rad.size());
  for (double x : angles_rad) a.push_back(x - turn * std::floor(x / turn));
  std::sort(a.begin(), a.end());
  std::vector<double> at;
  std::vector<double> count;
  for (double x : a) {
    if (!at.empty() && x - at.back() <= same) count.back() += 1.0;
    else at.push_back(x), count.push_back(1.0);
  }
  if (at.size() > 1 && at.front() + turn - at.back() <= same) {  // wraps past 360 deg
    count.front() += count.back();
    at.pop_back(), count.pop_back();
  }
  const auto N = static_cast<Eigen::Index>(at.size());
  R.distinct_angles = static_cast<int>(N);
  double widest_gap = N > 1 ? 0.0 : turn;
  bool even = N >= 3;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double gap = i + 1 < at.size() ? at[i + 1] - at[i] : at.front() + turn - at.back();
    widest_gap = std::max(widest_gap, gap);
    even = even && std::abs(gap - turn / static_cast<double>(N)) <= same;
  }
  R.span_deg = (turn - widest_gap) * 180.0 / M_PI;
  if (even) R.even_step_deg = 360.0 / static_cast<double>(N);

  // Weighted design, scaled so that an even full turn gives orthonormal columns.
  const double total = static_cast<double>(angles_rad.size());
  Eigen::MatrixXd H(N, 1 + 2 * max_order);
  for (Eigen::Index i = 0; i < N; ++i) {
    const double w = std::sqrt(count[static_cast<std::size_t>(i)] / total);
    const double th = at[static_cast<std::size_t>(i)];
    H(i, 0) = w;
    for (int k = 1; k <= max_order; ++k) {
      H(i, 2 * k - 1) = w * M_SQRT2 * std::cos(k * th);
      H(i, 2 * k) = w * M_SQRT2 * std::sin(k * th);
    }
  }
  R.resolved = max_order;
  for (int k = 1; k <= max_order; ++k) {
    // Orthonormal basis of the span of orders 0..k-1 (rank-revealing: once an order is
    // unresolvable the lower columns may be dependent), then what of order k lies outside it.
    Eigen::JacobiSVD<Eigen::MatrixXd> lower(H.leftCols(2 * k - 1), Eigen::ComputeThinU);
    Eigen::Index rank = 0;
    for (Eigen::Index i = 0; i < lower.singularValues().size(); ++i)
      rank += lower.singularValues()[i] > 1e-9 * std::max(1.0, lower.singularValues()[0]);
    const Eigen::MatrixXd U = lower.matrixU().leftCols(rank);
    const Eigen::MatrixXd pair = H.middleCols(2 * k - 1, 2);
    const Eigen::MatrixXd rest = pair - U * (U.transpose() * pair);
    double nc = 0.0;
    if (N - rank >= 2) {  // two new directions are needed at all (2k + 1 <= N)
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(rest);
      nc = svd.singularValues()[1];
      if (nc < 1e-9) nc = 0.0;  // rounding of an exactly dependent pair
    }
    R.new_content.push_back(nc);
    if (nc < min_new_content && R.resolved == max_order) R.resolved = k - 1;
  }
  return R;
}

std::string HarmonicResolution::why_not(int order) const {
  std::ostringstream out;
  out.precision(3);
  out << axis << " is sampled at " << distinct_angles << " distinct angle"
      << (distinct_angles == 1 ? "" : "s");
  if (even_step_deg > 0.0) out << ", " << even_step_deg << " deg apart over a full turn";
  else out << " spanning " << span_deg << " deg";
  if (order <= resolved || order > max_order) {
    out << ": order " << order << " is resolved";
    return out.str();
  }
  const int first = resolved + 1;
  const double nc = new_content[static_cast<std::size_t>(order - 1)];
  if (order > first && nc >= min_new_content) {
    out << ": order " << order << " is left out with the other orders above " << first - 1
        << ", since order " << first << " is not resolvable there";
    return out.str();
  }
  const int N = distinct_angles;
  if (even_step_deg > 0.0 && 2 * order >= N) {
    // Folding on an even grid: cos/sin of order k at th_i = i 2 pi/N equal those of k mod N,
    // and of N - (k mod N) with the sine's sign flipped.
    int alias = order % N;
    if (2 * alias > N) alias = N - alias;
    out << ", which resolves the orders below " << N / 2.0 << " (half the number of angles, the "
        << "Nyquist limit) only: order " << order;
    if (2 * alias == N)
      out << " is that limit: its sine vanishes at every sampled angle, so its amplitude and "
             "phase cannot be told apart";
    else if (alias == 0)
      out << " is constant at every sampled angle (an offset)";
    else
      out << " takes the same values there as order " << alias << " (aliasing)";
    return out.str();
  }
  if (2 * order + 1 > N)
    out << ": order " << order << " needs at least " << 2 * order + 1
        << " distinct angles to be told apart from the lower orders";
  else if (nc == 0.0)
    out << ": there order " << order << " is a combination of the lower orders (aliasing)";
  else
    out << ": there only " << 100.0 * nc << " % of order " << order
        << "'s signature is not a combination of the lower orders (" << 100.0 * min_new_content
        << " % needed)";
  return out.str();
}

double estimate_noise_um(const DiagnosisProblem& P, const Eigen::VectorXd& r) {
  const auto& g = P.groups();
  const auto& t = P.times();
  std::map<std::string, std::vector<std::size_t>> by_group;
  for (std::size_t i = 0; i < g.size(); ++i) by_group[g[i]].push_back(i);
  double ss = 0.0;
  std::size_t n = 0;
  for (auto& kv : by_group) {
    auto& idx = kv.second;
    std::stable_sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
    for (std::size_t k = 1; k < idx.size(); ++k) {
      const double d = r[static_cast<Eigen::Index>(idx[k])] - r[static_cast<Eigen::Index>(idx[k - 1])];
      ss += d * d;
      ++n;
    }
  }
  if (n == 0) throw InvalidArgument("estimate_noise_um: no group has two readings");
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
    for (Eigen::Index k = 0; k < y.size(); ++k) T(k, 0) = 1.0, T(k, 1) = t[idx[static_cast<std::size_t>(k)]];
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
      if (y.size() < 20) note << "only " << y.size() << " readings";
      else note << G.angle_axis << " sweeps " << span * 180.0 / M_PI << " deg, not a full turn";
      G.harmonic_note = note.str();
    }
    out.push_back(G);
  }
  return out;
}

namespace {

Diagnosis diagnose_at_noise(const DiagnosisProblem& P, const DiagnosisOptions& options,
                            std::optional<double> noise_override, const std::string& noise_source);

}  // namespace

Diagnosis diagnose(const DiagnosisProblem& P, const DiagnosisOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  Diagnosis D = diagnose_at_noise(P, options, std::nullopt, "");
  if (!P.declared_noise_um()) {
    // Successive differences overestimate the noise when the sampling is sparse against the
    // systematic errors (an R-test's 30 degree steps): if the extended model leaves less, that
    // is the better estimate, and the statistics are redone with it.
    const double n = static_cast<double>(D.final_fit.residuals.size());
    const double s_final =
        std::sqrt(D.final_fit.residuals.squaredNorm() / std::max(1.0, n - D.final_fit.num_free)) * 1e3;
    if (s_final < 0.8 * D.baseline.noise_um) {
      std::ostringstream why;
      why.precision(3);
      why << "estimated from the residuals of the extended model (successive differences gave "
          << D.baseline.noise_um << " um: the sampling is too sparse for them)";
      D = diagnose_at_noise(P, options, s_final, why.str());
    }
  }
  D.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return D;
}

namespace {

Diagnosis diagnose_at_noise(const DiagnosisProblem& P, const DiagnosisOptions& options,
                            std::optional<double> noise_override, const std::string& noise_source) {
  Diagnosis D;
  D.machine = P.machine();
  std::vector<Effect> candidates = P.candidates(options.max_harmonic);
  if (!options.only.empty()) {
    std::vector<Effect> keep;
    for (const std::string& id : options.only) {
      const Effect e = Effect::parse(id);
      if (std::find(candidates.begin(), candidates.end(), e) == candidates.end())
        throw InvalidArgument("options.only: " + id + " is not a candidate for this session");
      keep.push_back(e);
    }
    candidates = keep;
  }

  ModelFit fit = P.fit(EffectModel{});
  D.baseline_fit = fit;
  const double n = static_cast<double>(fit.residuals.size());
  const std::optional<double> declared = P.declared_noise_um();
  const double noise_um = declared ? *declared : noise_override ? *noise_override : estimate_noise_um(P, fit.residuals);
  const double sigma_mm = noise_um * 1e-3;
  D.baseline.noise_um = noise_um;
  D.baseline.noise_source = declared         ? "declared"
                            : noise_override ? noise_source
                                             : "estimated from successive differences";
  D.baseline.residual_rms_um = rms_um(fit.residuals);
  D.baseline.n = fit.residuals.size();
  D.baseline.dof = static_cast<int>(n) - fit.num_free;
  const double chi2 = rss(fit.residuals) / (sigma_mm * sigma_mm);
  D.baseline.chi2_per_dof = chi2 / D.baseline.dof;
  D.baseline.p_value = stats::chi2_sf(chi2, D.baseline.dof);
  D.structure_before = residual_structure(P, fit.residuals);

  // A *_hn candidate of an order its axis' sampling cannot resolve takes, at the sampled
  // angles, the values of lower orders (C every 30 deg: order 7 is order 5): scored, it would
  // name an order the data cannot tell. Judged on every reading's angle of that axis, since the
  // effect's parameters are shared by all of them.
  std::vector<std::string> unresolved(candidates.size());
  {
    std::map<char, int> top;
    for (const Effect& c : candidates)
      if (c.harmonic > 0) top[c.axis] = std::max(top[c.axis], c.harmonic);
    for (const auto& [axis, order] : top) {
      std::vector<double> th;
      for (const RotaryAngles<double>& r : P.angles()) th.push_back(axis == 'C' ? r.rot : r.tilt);
      const HarmonicResolution res =
          resolve_harmonics(th, axis, order, options.min_harmonic_new_content);
      for (std::size_t c = 0; c < candidates.size(); ++c)
        if (candidates[c].axis == axis && candidates[c].harmonic > res.resolved)
          unresolved[c] = "the sampling cannot resolve its harmonic order: " +
                          res.why_not(candidates[c].harmonic);
    }
  }

  const std::vector<int> fold = cv_folds(P, options.cv_blocks);
  EffectModel model;
  std::vector<bool> done(candidates.size(), false);
  bool first_round = true;
  for (int step = 0; step < options.max_findings; ++step) {
    const Eigen::MatrixXd Jfree = free_columns(fit.jacobian);
    const Eigen::MatrixXd Q = orthonormal_basis(Jfree);
    std::vector<Score> scores;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      if (done[c]) continue;
      if (!unresolved[c].empty()) {
        D.unobservable.push_back({candidates[c].id(), unresolved[c]});
        done[c] = true;
        continue;
      }
      Score s = score(P, fit, Jfree, Q, candidates[c], sigma_mm, options.min_visible_chi2);
      if (!s.observable) {
        if (first_round) D.unobservable.push_back({candidates[c].id(), s.why_not});
        done[c] = true;
        continue;
      }
      scores.push_back(std::move(s));
    }
    first_round = false;
    std::vector<CandidateScore> table;
    for (const Score& s : scores)
      table.push_back({s.effect.id(), s.k, s.delta_bic, s.f_pvalue, std::sqrt(s.rss1 / n) * 1e3});
    std::sort(table.begin(), table.end(),
              [](const CandidateScore& a, const CandidateScore& b) { return a.delta_bic < b.delta_bic; });
    D.rounds.push_back(std::move(table));
    const double m_tests = std::max<double>(1.0, static_cast<double>(scores.size()));
    std::vector<const Score*> passing;
    for (const Score& s : scores)
      if (s.f_pvalue < options.alpha / m_tests && s.delta_bic < options.min_delta_bic) passing.push_back(&s);
    std::sort(passing.begin(), passing.end(),
              [](const Score* a, const Score* b) { return a->delta_bic < b->delta_bic; });
    const Score* chosen = nullptr;
    double cv_before = 0.0, cv_after = 0.0;
    for (const Score* s : passing) {
      cv_before = cv_rms_um(Jfree, fit.residuals, fold, options.cv_blocks);
      cv_after = cv_rms_um(s->X, fit.residuals, fold, options.cv_blocks);
      if (cv_after < cv_before) {
        chosen = s;
        break;
      }
    }
    if (!chosen) break;

    // Candidates that explain the same signal about as well.
    Ambiguity amb;
    for (const Score* s : passing) {
      if (s == chosen) continue;
      const double dbic = s->delta_bic - chosen->delta_bic;
      const double corr = std::abs(correlation(s->signature, chosen->signature));
      if (dbic < options.ambiguity_delta_bic && corr >= options.ambiguity_correlation) {
        if (amb.effects.empty()) amb.effects.push_back(chosen->effect.id());
        amb.effects.push_back(s->effect.id());
        amb.delta_bic = std::max(amb.delta_bic, dbic);
        amb.correlation = amb.effects.size() == 2 ? corr : std::min(amb.correlation, corr);
        amb.separating_test = separating_test(P, fit, *chosen, *s, sigma_mm);
      }
    }
    if (!amb.effects.empty()) D.ambiguous.push_back(amb);

    // Add it and refit the whole model (nonlinear).
    const Effect effect = chosen->effect;
    for (std::size_t c = 0; c < candidates.size(); ++c)
      if (candidates[c] == effect) done[c] = true;
    model.effects.push_back(effect);
    const double rss_before = rss(fit.residuals);
    const double rms_before = rms_um(fit.residuals);
    const double f_p = chosen->f_pvalue;
    const ModelFit before = fit;
    fit = P.fit(model);
    Finding F;
    F.effect = effect;
    F.cause = effect.cause();
    F.gain.rms_before_um = rms_before;
    F.gain.rms_after_um = rms_um(fit.residuals);
    F.gain.delta_bic = n * std::log(std::max(rss(fit.residuals), 1e-300) / rss_before) +
                       (fit.num_free - before.num_free) * std::log(n);
    F.gain.cv_rms_before_um = cv_before;
    F.gain.cv_rms_after_um = cv_after;
    F.gain.f_pvalue = f_p;
    for (const ParameterEstimate& b : before.parameters) {
      for (const ParameterEstimate& a : fit.parameters) {
        if (a.name != b.name || !a.observable || !b.observable) continue;
        if (std::abs(a.value - b.value) > std::max(a.std, 1e-15))
          F.shifts.push_back({a.name, b.value, a.value, a.std, a.unit});
      }
    }
    D.findings.push_back(F);
  }

  // Effect parameters from the final fit.
  for (Finding& F : D.findings) {
    const std::string id = F.effect.id();
    for (const ParameterEstimate& p : fit.parameters)
      if (p.name == id || p.name.rfind(id + ".", 0) == 0) F.parameters.push_back(p);
  }
  D.final_fit = fit;
  D.structure_after = residual_structure(P, fit.residuals);
  const int dof = static_cast<int>(n) - fit.num_free;
  const double chi2_final = rss(fit.residuals) / (sigma_mm * sigma_mm);
  D.unexplained.chi2_per_dof = chi2_final / dof;
  D.unexplained.p_value = stats::chi2_sf(chi2_final, dof);
  D.unexplained.present = D.unexplained.p_value < 1e-3;
  if (D.unexplained.present) D.unexplained.signature = describe_structure(D.structure_after);
  return D;
}

}  // namespace

}  // namespace rotacal
