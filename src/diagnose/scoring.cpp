// SPDX-License-Identifier: BSD-3-Clause
// Scoring of candidate effects: least-squares helpers, the linearised refit with its delta
// BIC and F-test, and blocked cross-validation.
#include "scoring.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <map>

#include "rotacal/core/error.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/core/stats.hpp"

namespace rotacal::diagnosis_detail {

double rss(const Eigen::VectorXd& r) { return r.squaredNorm(); }
double rms_um(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / static_cast<double>(r.size())) * 1e3 : 0.0;
}

// The plausible size of each parameter (DiagnosisOptions::min_visible_chi2): the unit's
// (1 mm, 1 mrad, ...), but 10 um for a touch probe's lobing: a kinematic probe's three-lobed
// pretravel variation is a few um before its calibration (the budget's default after it is
// 0.5 um, uncertainty_budget.hpp), and at 1 mm a lobing the touch layout turns into a sphere
// shift (four horizontal touches 90 deg apart) stayed "visible" through its remainder.
Eigen::VectorXd magnitudes(const Effect& c) {
  const auto units = c.param_units();
  Eigen::VectorXd m(static_cast<Eigen::Index>(units.size()));
  for (std::size_t k = 0; k < units.size(); ++k)
    m[static_cast<Eigen::Index>(k)] =
        c.kind == EffectKind::probe_lobing ? 10e-3 : plausible_magnitude(units[k]);
  return m;
}

Eigen::VectorXd solve_ls(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  if (X.cols() == 0) return Eigen::VectorXd();
  Eigen::VectorXd s = X.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < s.size(); ++j)
    if (!(s[j] > 0.0)) s[j] = 1.0;
  const Eigen::MatrixXd Xs = X * s.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Xs);
  qr.setThreshold(1e-9);
  // No column the data see (a candidate of an axis that never moves in this session): the
  // least-squares answer is zero, where Eigen's solve of a rank-0 QR gives NaN.
  if (qr.rank() == 0) return Eigen::VectorXd::Zero(X.cols());
  return (qr.solve(y)).cwiseQuotient(s);
}

Eigen::MatrixXd orthonormal_basis(Eigen::MatrixXd J) {
  if (J.cols() == 0) return Eigen::MatrixXd(J.rows(), 0);
  Eigen::VectorXd s = J.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < s.size(); ++j)
    if (!(s[j] > 0.0)) s[j] = 1.0;
  // In place (J by value: a caller's temporary is taken over): J's columns scaled, then J holds
  // the factors. An n x p copy each saved, which a 1 kHz recording's round start needs.
  J.array().rowwise() /= s.transpose().array();
  Eigen::ColPivHouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(J);
  qr.setThreshold(1e-9);
  const Eigen::Index r = qr.rank();
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(J.rows(), r);
  qr.householderQ().applyThisOnTheLeft(Q);
  return Q;
}

Eigen::MatrixXd orthonormal_basis_full_rank(const Eigen::MatrixXd& J) {
  const Eigen::Index p = J.cols();
  if (p == 0) return Eigen::MatrixXd(J.rows(), 0);
  Eigen::MatrixXd Q = J;
  for (int pass = 0; pass < 2; ++pass) {  // CholeskyQR2: the second pass restores orthogonality
    const Eigen::MatrixXd G = gram_matrix(Q);
    const Eigen::VectorXd d = G.diagonal().cwiseSqrt();
    if (!(d.minCoeff() > 0.0) || !d.allFinite()) return orthonormal_basis(J);
    const Eigen::MatrixXd Gn = d.cwiseInverse().asDiagonal() * G * d.cwiseInverse().asDiagonal();
    const Eigen::LLT<Eigen::MatrixXd> llt(Gn);
    // Near rank deficiency (condition of the normalised columns above ~1e6) the rank-revealing
    // QR decides, as everywhere else.
    if (llt.info() != Eigen::Success || !(llt.matrixLLT().diagonal().minCoeff() > 1e-6))
      return orthonormal_basis(J);
    Q = Q * d.cwiseInverse().asDiagonal();
    llt.matrixU().solveInPlace<Eigen::OnTheRight>(Q);
    // One pass leaves Q^T Q - I of about cond(Gn) * 1e-16: with cond(Gn) under 1e4 that is
    // 1e-12 already, and the second pass (half of the work) would not change a decision.
    if (pass == 0 && llt.rcond() > 1e-4) break;
  }
  return Q;
}

Eigen::MatrixXd project_out(const Eigen::MatrixXd& Q, const Eigen::MatrixXd& C) {
  return C - Q * (Q.transpose() * C);
}

Eigen::VectorXd residual_without(const Eigen::MatrixXd& Q, const Eigen::VectorXd& r,
                                 const Eigen::VectorXd& Qr, const Eigen::MatrixXd& Jc) {
  const Eigen::MatrixXd A = Q.transpose() * Jc;
  const Eigen::MatrixXd Gc = gram_matrix(Jc);
  const Eigen::MatrixXd G = Gc - A.transpose() * A;
  const Eigen::VectorXd d = G.diagonal().cwiseMax(0.0).cwiseSqrt();
  // A column keeping a fraction f of its norm outside the span loses -2 log10(f) of 16 digits
  // in Jp^T Jp: up to 1e-5 (6 digits left) that is far below what a noise model resolves.
  // About a tenth of a ballbar session's candidates keep less (down to 1e-7) and go the
  // column way.
  if (!((d.array() > 1e-5 * Gc.diagonal().cwiseSqrt().array()).all())) return {};
  const Eigen::VectorXd di = d.cwiseInverse();
  const Eigen::LLT<Eigen::MatrixXd> llt(di.asDiagonal() * G * di.asDiagonal());
  if (llt.info() != Eigen::Success || !(llt.matrixLLT().diagonal().minCoeff() > 1e-3)) return {};
  const Eigen::VectorXd b =
      di.asDiagonal() * llt.solve(di.asDiagonal() * (Jc.transpose() * r - A.transpose() * Qr));
  return r - Jc * b + Q * (A * b);
}

// Free (non-zero) columns of a fit's Jacobian.
Eigen::MatrixXd free_columns(const Eigen::MatrixXd& J) {
  std::vector<Eigen::Index> keep;
  for (Eigen::Index j = 0; j < J.cols(); ++j)
    if (J.col(j).squaredNorm() > 0.0) keep.push_back(j);
  Eigen::MatrixXd out(J.rows(), static_cast<Eigen::Index>(keep.size()));
  for (std::size_t k = 0; k < keep.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = J.col(keep[k]);
  return out;
}

ColumnScore score_columns(const Eigen::VectorXd& m, const CandidateGrams& g, int num_free,
                          int nonlinear, double min_chi2, double tol) {
  ColumnScore s;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(g.perp);
  if (es.info() != Eigen::Success) {
    s.decided = false;
    return s;
  }
  const Eigen::VectorXd& ev = es.eigenvalues();
  std::vector<Eigen::Index> dirs;
  for (Eigen::Index i = 0; i < ev.size(); ++i) {
    if (std::abs(ev[i] - min_chi2) < tol) {
      s.decided = false;
      return s;
    }
    if (ev[i] >= min_chi2) dirs.push_back(i);
  }
  if (dirs.empty()) {
    const Eigen::VectorXd ev_raw =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(g.raw, Eigen::EigenvaluesOnly).eigenvalues();
    const double top = ev_raw.size() ? ev_raw.maxCoeff() : 0.0;
    s.decided = !(std::abs(top - min_chi2) < tol);
    s.absorbed = top >= min_chi2;
    return s;
  }
  s.visible = true;
  s.k = static_cast<int>(dirs.size());
  s.V.resize(m.size(), s.k);
  Eigen::VectorXd lambda(s.k);
  for (int i = 0; i < s.k; ++i) {
    s.V.col(i) = es.eigenvectors().col(dirs[static_cast<std::size_t>(i)]);
    lambda[i] = ev[dirs[static_cast<std::size_t>(i)]];
  }
  // A = perp_columns V has orthogonal columns of squared norms lambda: d = A' r_w / lambda.
  const Eigen::VectorXd Atr = s.V.transpose() * g.perp_r;
  s.d = Atr.cwiseQuotient(lambda);
  s.params = m.cwiseProduct(s.V * s.d);
  s.rss1 = std::max(g.rr - Atr.dot(s.d), 1e-300);
  const int k_all = s.k + nonlinear;
  s.delta_bic = g.n * std::log(s.rss1 / g.rr) + k_all * std::log(g.n);
  const double dof = g.n - num_free - k_all;
  const double F = ((g.rr - s.rss1) / s.k) / (s.rss1 / dof);
  s.f_pvalue = stats::f_sf(std::max(F, 0.0), s.k, dof);
  return s;
}

double blocked_cv_rms_um(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                         const std::vector<int>& fold, int K, const FoldFit& fit) {
  double ss = 0.0;
  std::size_t n = 0;
  for (int k = 0; k < K; ++k) {
    std::vector<Eigen::Index> tr, te;
    for (std::size_t i = 0; i < fold.size(); ++i)
      (fold[i] == k ? te : tr).push_back(static_cast<Eigen::Index>(i));
    if (te.empty() || tr.empty()) continue;
    const Eigen::VectorXd d = fit(tr);
    for (Eigen::Index i : te) {
      const double e = y[i] - (X.cols() ? X.row(i).dot(d) : 0.0);
      ss += e * e;
      ++n;
    }
  }
  return n ? std::sqrt(ss / static_cast<double>(n)) * 1e3 : 0.0;
}

std::vector<int> cv_folds(const DiagnosisProblem& P, int K, const NoiseModel* noise) {
  const auto& g = P.groups();
  const auto& t = P.times();
  std::map<std::string, std::vector<std::size_t>> by_group;
  for (std::size_t i = 0; i < g.size(); ++i) by_group[g[i]].push_back(i);
  // Blocks at least one correlation time long (in the group's readings: a time stamp with
  // three channels is three readings), so a left-out block's noise is nearly independent of
  // the noise the refit saw.
  std::map<std::string, double> min_block;
  if (noise) {
    std::map<std::string, int> channels;
    for (const NoiseStream& s : noise->streams) {
      channels[s.group] = std::max(channels[s.group], s.channel + 1);
      min_block[s.group] = std::max(min_block[s.group], s.correlation_samples);
    }
    for (auto& kv : min_block) kv.second *= channels[kv.first];
  }
  std::vector<int> fold(g.size(), 0);
  // Group j's blocks go to folds j, j+1, ...: no fold holds the start of every test, so a
  // signal that sits at each test's start (a reversal spike) is never left out all at once.
  int group_index = 0;
  for (auto& kv : by_group) {
    const int shift = group_index++;
    auto& idx = kv.second;
    std::stable_sort(idx.begin(), idx.end(),
                     [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
    int blocks = K;
    const auto it = min_block.find(kv.first);
    if (it != min_block.end() && it->second > 1.0)
      blocks = std::clamp(static_cast<int>(static_cast<double>(idx.size()) / it->second), 2, K);
    for (std::size_t k = 0; k < idx.size(); ++k)
      fold[idx[k]] = contiguous_block(k, idx.size(), blocks, shift);
  }
  return fold;
}

double cv_rms_um(const Eigen::MatrixXd& X, const Eigen::VectorXd& r, const std::vector<int>& fold,
                 int K) {
  return blocked_cv_rms_um(X, r, fold, K, [&](const std::vector<Eigen::Index>& train) {
    return solve_ls(X(train, Eigen::all), r(train));
  });
}

namespace {

// The score of candidate c from its Gram quantities per plausible size (score_columns), with
// why a candidate that is not observable is not. nullopt where score_columns cannot decide.
// V and d: the observable directions and their coefficients.
std::optional<Score> score_from_grams(const Effect& c, const Eigen::VectorXd& m,
                                      const CandidateGrams& g, int num_free, double min_chi2,
                                      double tol, Eigen::MatrixXd* V_out = nullptr,
                                      Eigen::VectorXd* d_out = nullptr) {
  ColumnScore cs = score_columns(m, g, num_free, 0, min_chi2, tol);
  if (!cs.decided) return std::nullopt;
  Score s;
  s.effect = c;
  if (!cs.visible) {
    s.why_not = cs.absorbed
                    ? "its effect on these readings is indistinguishable from the location "
                      "errors and set-up parameters already in the model"
                    : "at any plausible size it changes these readings by less than 5 sigma "
                      "in all (e.g. a motion perpendicular to the bar)";
    return s;
  }
  s.observable = true;
  s.k = cs.k;
  s.directions = m.asDiagonal() * cs.V;
  s.params = std::move(cs.params);
  s.rss1 = cs.rss1;
  s.delta_bic = cs.delta_bic;
  s.f_pvalue = cs.f_pvalue;
  if (V_out) *V_out = std::move(cs.V);
  if (d_out) *d_out = std::move(cs.d);
  return s;
}

}  // namespace

Score score(const ScoringInputs& in, const Effect& c, Eigen::MatrixXd Jc_w, double min_chi2,
            double columns_below_delta_bic) {
  const Eigen::VectorXd m = magnitudes(c);
  if (!Jc_w.allFinite()) {  // e.g. a time constant over readings that all share one time stamp
    Score s;
    s.effect = c;
    s.why_not = kUndefinedOnReadings;
    return s;
  }
  // Per plausible size (columns scaled by m), the whitened columns' Gram matrix before and after
  // the model is projected out. Eigenvalues rather than an SVD of the n x k columns: the
  // threshold min_chi2 sits far above their rounding (eps times the largest), and a 1 kHz
  // recording cannot afford the SVD's copies.
  CandidateGrams g;
  g.raw = m.asDiagonal() * (Jc_w.transpose() * Jc_w) * m.asDiagonal();
  Jc_w -= in.Q_w * (in.Q_w.transpose() * Jc_w);  // in place: the model projected out
  Jc_w *= m.asDiagonal();
  const Eigen::MatrixXd& perp = Jc_w;
  g.perp = perp.transpose() * perp;
  g.perp_r = perp.transpose() * in.r_w;
  g.rr = rss(in.r_w);
  g.n = static_cast<double>(in.r_w.size());
  Eigen::MatrixXd V;
  Eigen::VectorXd d;
  std::optional<Score> got = score_from_grams(c, m, g, in.num_free, min_chi2, 0.0, &V, &d);
  if (!got)  // not with finite columns
    throw DegenerateGeometry("score: the Gram matrix of candidate " + c.id() +
                             " has no eigen decomposition");
  Score s = std::move(*got);
  if (s.observable && s.delta_bic < columns_below_delta_bic) {
    s.A = perp * V;
    s.signature = s.A * d;
  }
  return s;
}

ModelProducts::ModelProducts(const Eigen::MatrixXd& Jf,
                             std::vector<std::vector<Eigen::Index>> streams)
    : lags(Jf, std::move(streams)), gram(Jf.transpose() * Jf) {}

CandidateProducts candidate_products(const ArWhitener* W, double sigma_mm,
                                     const ModelProducts& model, const Eigen::MatrixXd& Jf,
                                     const Eigen::MatrixXd& Jc, const Eigen::VectorXd& r) {
  const Eigen::Index k = Jc.cols();
  Eigen::MatrixXd MX(Jc.rows(), k + 1);  // V^-1 [Jc r]
  MX << Jc, r;
  CandidateProducts g;
  if (W) {
    W->apply_inverse_covariance(MX);
    g.G_ff = W->gram(model.lags);
  } else {
    const double inv_var = 1.0 / (sigma_mm * sigma_mm);
    MX *= inv_var;
    g.G_ff = model.gram * inv_var;
  }
  const Eigen::MatrixXd fX = Jf.transpose() * MX;
  g.g_fc = fX.leftCols(k);
  g.g_fr = fX.col(k);
  g.G_cc = Jc.transpose() * MX.leftCols(k);
  g.g_cr = Jc.transpose() * MX.col(k);
  g.rr = r.dot(MX.col(k));
  g.n = r.size();
  return g;
}

std::optional<Score> score_from_products(const CandidateProducts& g, const Effect& c, int num_free,
                                         double min_chi2) {
  const Eigen::VectorXd m = magnitudes(c);
  // Y = L^-1 D^-1 g_fc with D^-1 G_ff D^-1 = L L^T: then Y^T Y is the part of the candidate's
  // Gram matrix that the model's columns explain (the normalised Cholesky test is
  // orthonormal_basis_full_rank's, stricter: cancellation in G_cc - Y^T Y grows with the
  // condition number, which rounding must not let decide a threshold).
  Eigen::MatrixXd Y = g.g_fc;
  Eigen::VectorXd yr = g.g_fr;
  if (g.G_ff.rows() > 0) {
    const Eigen::VectorXd d = g.G_ff.diagonal().cwiseSqrt();
    if (!(d.minCoeff() > 0.0) || !d.allFinite()) return std::nullopt;
    const Eigen::VectorXd di = d.cwiseInverse();
    const Eigen::LLT<Eigen::MatrixXd> llt(di.asDiagonal() * g.G_ff * di.asDiagonal());
    if (llt.info() != Eigen::Success || !(llt.matrixLLT().diagonal().minCoeff() > 1e-3))
      return std::nullopt;
    Y = di.asDiagonal() * Y;
    llt.matrixL().solveInPlace(Y);
    yr = di.asDiagonal() * yr;
    llt.matrixL().solveInPlace(yr);
  }
  // Per plausible size: raw = the candidate's whitened Gram matrix, perp = after projecting
  // out the model (as score() forms them from the columns).
  CandidateGrams grams;
  grams.raw = m.asDiagonal() * g.G_cc * m.asDiagonal();
  grams.perp = m.asDiagonal() * (g.G_cc - Y.transpose() * Y) * m.asDiagonal();
  grams.perp_r = m.asDiagonal() * (g.g_cr - Y.transpose() * yr);
  grams.rr = g.rr;
  grams.n = static_cast<double>(g.n);
  const double tol = 1e-8 * std::max(grams.raw.norm(), min_chi2);
  return score_from_grams(c, m, grams, num_free, min_chi2, tol);
}

double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double na = a.norm(), nb = b.norm();
  return na > 0 && nb > 0 ? a.dot(b) / (na * nb) : 0.0;
}

}  // namespace rotacal::diagnosis_detail
