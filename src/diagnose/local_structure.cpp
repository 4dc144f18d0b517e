// SPDX-License-Identifier: BSD-3-Clause
// Structure the final model leaves in a few consecutive poses, and the findings whose evidence
// lies in it (local_structure.hpp).
#include "local_structure.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "rotacal/core/noise_handling.hpp"
#include "rotacal/core/stats.hpp"
#include "search.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// [A B] by blocks: Eigen's comma initializer asserts on a block without columns (or rows).
Eigen::MatrixXd side_by_side(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  Eigen::MatrixXd X(A.rows(), A.cols() + B.cols());
  X.leftCols(A.cols()) = A;
  X.rightCols(B.cols()) = B;
  return X;
}

// The final model's free columns and, for 1/f-like noise, one level per stream (nuisance, as
// in the structure test of final_test.cpp), with the noise the final model leaves: white with
// the diagnosis' sigma, or by REML over what that model leaves.
struct FinalModel {
  Eigen::MatrixXd X;  // free columns (+ levels)
  Eigen::MatrixXd levels;
  NoiseTreatment noise;
};
FinalModel final_model(const DiagnosisProblem& P, const Diagnosis& D) {
  FinalModel M;
  M.X = free_columns(D.final_fit.jacobian);
  if (D.noise.white()) {
    M.noise.sigma_mm = D.baseline.noise_um * 1e-3;
    return M;
  }
  if (D.noise.max_order >= 2) {
    M.levels = stream_levels(P);
    M.X = side_by_side(M.X, M.levels);
  }
  M.noise =
      coloured_treatment(estimate_noise_model_reml(D.noise, D.final_fit.residuals, M.X), false);
  return M;
}

Eigen::MatrixXd window_columns(const std::vector<LocalBlock>& blocks, std::size_t first,
                               std::size_t count, Eigen::Index n) {
  Eigen::Index k = 0;
  for (std::size_t b = first; b < first + count; ++b) k += blocks[b].columns.cols();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, k);
  Eigen::Index c = 0;
  for (std::size_t b = first; b < first + count; ++b) {
    const LocalBlock& B = blocks[b];
    for (std::size_t i = 0; i < B.rows.size(); ++i)
      G.block(B.rows[i], c, 1, B.columns.cols()) = B.columns.row(static_cast<Eigen::Index>(i));
    c += B.columns.cols();
  }
  return G;
}

struct Window {
  std::size_t first = 0, count = 0;
  double p = 1.0;
};

// The F-test of a window's free shifts on the whitened residual r_w beside the model's
// whitened basis Q (free parameters: num_free).
double window_p(const Eigen::MatrixXd& Q, const Eigen::VectorXd& r_w, const Eigen::MatrixXd& G_w,
                double num_free) {
  const Eigen::MatrixXd B = orthonormal_basis(project_out(Q, G_w));
  const auto q = static_cast<double>(B.cols());
  const double dof = static_cast<double>(r_w.size()) - num_free - q;
  if (q == 0 || dof <= 0) return 1.0;
  const double ss = (B.transpose() * r_w).squaredNorm();
  const double rest = std::max(r_w.squaredNorm() - ss, 1e-300);
  return stats::f_sf(std::max((ss / q) / (rest / dof), 0.0), q, dof);
}

// The window's shifts (mm) fitted to y_mm beside the columns `model`, linearised at the final fit.
Eigen::VectorXd window_shift_mm(const FinalModel& M, const Eigen::MatrixXd& model,
                                const Eigen::VectorXd& y_mm, const Eigen::MatrixXd& G) {
  return solve_ls(M.noise.whiten(side_by_side(model, G)), M.noise.whiten(y_mm)).tail(G.cols());
}

// Where the window is, in words, and as D.unexplained's axis and range.
std::string describe(const DiagnosisProblem& P, const std::vector<LocalBlock>& blocks,
                     const Window& w, const Eigen::VectorXd& shift_mm, Unexplained& U) {
  const LocalBlock& a = blocks[w.first];
  const LocalBlock& b = blocks[w.first + w.count - 1];
  double lo_r = 1e300, hi_r = -1e300, lo_t = 1e300, hi_t = -1e300;
  for (std::size_t k = w.first; k < w.first + w.count; ++k) {
    lo_r = std::min(lo_r, blocks[k].rot_deg), hi_r = std::max(hi_r, blocks[k].rot_deg);
    lo_t = std::min(lo_t, blocks[k].tilt_deg), hi_t = std::max(hi_t, blocks[k].tilt_deg);
  }
  const char tilt = tilt_axis_letter(P.machine());
  std::ostringstream out;
  out.precision(4);
  out << "local structure in pose" << (w.count > 1 ? "s '" : " '") << a.label << "'"
      << (w.count > 1 ? "..'" + b.label + "'" : std::string()) << " (" << tilt << " " << lo_t;
  if (hi_t > lo_t) out << ".." << hi_t;
  out << " deg, C " << lo_r;
  if (hi_r > lo_r) out << ".." << hi_r;
  out << " deg, t " << a.t_from << ".." << b.t_to << " s): a free shift of "
      << (w.count > 1 ? "these poses" : "this pose")
      << " explains what the catalogue does not (p = ";
  out.precision(2);
  out << w.p << " over every window of up to " << kMaxWindow << " poses; largest shift component "
      << shift_mm.cwiseAbs().maxCoeff() * 1e3 << " um)";
  U.group = P.groups()[static_cast<std::size_t>(a.rows.front())];
  const bool sweeps_c = hi_r > lo_r && !(hi_t > lo_t), sweeps_tilt = hi_t > lo_t && !(hi_r > lo_r);
  U.axis = sweeps_c ? 'C' : sweeps_tilt ? tilt : 0;
  U.range_from = sweeps_c ? lo_r : sweeps_tilt ? lo_t : a.t_from;
  U.range_to = sweeps_c ? hi_r : sweeps_tilt ? hi_t : b.t_to;
  return out.str();
}

// The finding's own share of the final model: its fitted signature (its columns times its
// values; a time constant's column times its logarithm is no share of it, d (1 - e^-t/tau) is
// the amplitude's column times d) and the free columns of every other parameter.
struct Share {
  Eigen::VectorXd signature;
  Eigen::MatrixXd own, others;  // free columns
};
Share share_of(const ModelFit& fit, const Effect& effect) {
  const std::string id = effect.id();
  Share S;
  S.signature = Eigen::VectorXd::Zero(fit.jacobian.rows());
  std::vector<Eigen::Index> own, others;
  for (Eigen::Index j = 0; j < fit.jacobian.cols(); ++j) {
    if (fit.jacobian.col(j).squaredNorm() == 0.0) continue;
    const ParameterEstimate& p = fit.parameters[static_cast<std::size_t>(j)];
    const bool mine = p.name == id || p.name.rfind(id + ".", 0) == 0;
    (mine ? own : others).push_back(j);
    if (mine && p.name.find(".ln_tau") == std::string::npos)
      S.signature += fit.jacobian.col(j) * p.value;
  }
  S.own.resize(fit.jacobian.rows(), static_cast<Eigen::Index>(own.size()));
  S.others.resize(fit.jacobian.rows(), static_cast<Eigen::Index>(others.size()));
  for (std::size_t k = 0; k < own.size(); ++k)
    S.own.col(static_cast<Eigen::Index>(k)) = fit.jacobian.col(own[k]);
  for (std::size_t k = 0; k < others.size(); ++k)
    S.others.col(static_cast<Eigen::Index>(k)) = fit.jacobian.col(others[k]);
  return S;
}

// The local rival of a finding: its own signature, free in each pose of a window of 1..kMaxWindow
// consecutive poses and zero elsewhere, in its place ("this shape, but only here"). The smallest
// IC(rival) - IC(finding) over the windows at an Occam term of c per parameter (chi-square
// whitened under the final model's noise, scaled by its chi-square per dof where that exceeds 1).
struct LocalRival {
  double delta_bic = 1e300, delta_aic = 1e300;
  Window window_bic, window_aic;
  Eigen::MatrixXd others;  // the model's columns without the finding's (+ levels)
  Eigen::VectorXd y_mm;    // the final residuals with the finding's signature put back
};
LocalRival local_rival(const Diagnosis& D, const FinalModel& M,
                       const std::vector<LocalBlock>& blocks, const Finding& F) {
  const Share S = share_of(D.final_fit, F.effect);
  const Eigen::Index n = S.signature.size();
  LocalRival out;
  out.others = M.levels.cols() > 0 ? side_by_side(S.others, M.levels) : S.others;
  out.y_mm = D.final_fit.residuals + S.signature;
  const Eigen::MatrixXd Q = orthonormal_basis(M.noise.whiten(out.others));
  const Eigen::VectorXd y = M.noise.whiten(out.y_mm);
  const Eigen::VectorXd y_perp = y - Q * (Q.transpose() * y);
  const Eigen::MatrixXd B_own = orthonormal_basis(project_out(Q, M.noise.whiten(S.own)));
  const double rss_f = y_perp.squaredNorm() - (B_own.transpose() * y_perp).squaredNorm();
  const double dof = static_cast<double>(n - Q.cols() - B_own.cols());
  const double scale = dof > 0 ? std::max(1.0, rss_f / dof) : 1.0;
  const auto k = static_cast<double>(B_own.cols());
  for (std::size_t count = 1;
       count <= static_cast<std::size_t>(kMaxWindow) && count <= blocks.size(); ++count)
    for (std::size_t first = 0; first + count <= blocks.size(); ++first) {
      Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(count));
      for (std::size_t b = 0; b < count; ++b)
        for (Eigen::Index i : blocks[first + b].rows)
          G(i, static_cast<Eigen::Index>(b)) = S.signature[i];
      const Eigen::MatrixXd B = orthonormal_basis(project_out(Q, M.noise.whiten(G)));
      const double rss_w = y_perp.squaredNorm() - (B.transpose() * y_perp).squaredNorm();
      const auto q = static_cast<double>(B.cols());
      const double d_bic = (rss_w - rss_f) / scale + (q - k) * std::log(static_cast<double>(n));
      const double d_aic = (rss_w - rss_f) / scale + (q - k) * 2.0;
      // The window's own evidence: its columns' F-test beside the other parameters.
      const double dof_w = static_cast<double>(n - Q.cols()) - q;
      const double p =
          q > 0 && dof_w > 0
              ? stats::f_sf(std::max(0.0, ((y_perp.squaredNorm() - rss_w) / q) / (rss_w / dof_w)),
                            q, dof_w)
              : 1.0;
      if (d_bic < out.delta_bic) out.delta_bic = d_bic, out.window_bic = {first, count, p};
      if (d_aic < out.delta_aic) out.delta_aic = d_aic, out.window_aic = {first, count, p};
    }
  return out;
}

// The window as D's unexplained structure (appended to the structure the engine found, if any).
void report(const DiagnosisProblem& P, const std::vector<LocalBlock>& blocks, const Window& w,
            const Eigen::VectorXd& shift_mm, Diagnosis& D) {
  Unexplained where;
  const std::string what = describe(P, blocks, w, shift_mm, where);
  if (D.unexplained.present) {
    D.unexplained.signature += "; " + what;
    return;
  }
  D.unexplained.present = true;
  D.unexplained.p_value = w.p;
  D.unexplained.group = where.group;
  D.unexplained.axis = where.axis;
  D.unexplained.range_from = where.range_from;
  D.unexplained.range_to = where.range_to;
  D.unexplained.signature = what;
}

}  // namespace

void judge_local_structure(const DiagnosisProblem& P, const std::vector<LocalBlock>& blocks,
                           const DiagnosisOptions& options, Diagnosis& D) {
  const Eigen::VectorXd& r = D.final_fit.residuals;
  if (blocks.empty() || r.size() == 0) return;
  const FinalModel M = final_model(P, D);
  const Eigen::MatrixXd Q = orthonormal_basis(M.noise.whiten(M.X));
  const Eigen::VectorXd r_w = M.noise.whiten(r);
  Window best;
  int windows = 0;
  for (std::size_t count = 1;
       count <= static_cast<std::size_t>(kMaxWindow) && count <= blocks.size(); ++count)
    for (std::size_t first = 0; first + count <= blocks.size(); ++first, ++windows) {
      const double p =
          window_p(Q, r_w, M.noise.whiten(window_columns(blocks, first, count, r.size())),
                   static_cast<double>(Q.cols()));
      if (p < best.p) best = {first, count, p};
    }
  best.p = std::min(1.0, best.p * windows);
  // Every finding weighed against its local rival, as against the catalogue's (rivals.hpp): its
  // weight among itself, its rivals and the local rival is 1 / (1 / w + e^(-delta / 2)) at
  // either Occam term, the smaller of the two.
  std::vector<std::pair<Window, LocalRival>> demoted;
  for (Finding& F : D.findings) {
    LocalRival L = local_rival(D, M, blocks, F);
    const double w = std::min(1.0 / (1.0 / F.weight + std::exp(-0.5 * L.delta_bic)),
                              1.0 / (1.0 / F.weight + std::exp(-0.5 * L.delta_aic)));
    if (w >= options.min_weight) continue;
    // A finding its catalogue rivals already left without a name takes the local rival's share
    // of the weight; the local rival took its name, or explains the readings as well, only
    // where it does. Before, every such finding was told so and its window reported as
    // unexplained structure, at a p of up to 1 (every ambiguous first finding of the probe
    // bench's AR(1) 0.5, 3x sessions, whatever the local rival's IC).
    const double before = F.weight;
    const bool took_name = before >= options.min_weight;
    const bool as_well = std::min(L.delta_bic, L.delta_aic) <= 0.0;
    F.weight = w;
    if (!took_name && !as_well) continue;
    Window at = L.delta_aic < L.delta_bic ? L.window_aic : L.window_bic;
    std::ostringstream why;
    why.precision(2);
    why << "its signature only in pose" << (at.count > 1 ? "s '" : " '") << blocks[at.first].label
        << "'"
        << (at.count > 1 ? "..'" + blocks[at.first + at.count - 1].label + "'" : std::string())
        << " and nowhere else fits the readings as well (weight " << w << " against " << before
        << " before): a local defect there, outside the catalogue, explains them at least as well";
    F.lack_of_fit = why.str();
    at.p = std::min(1.0, at.p * windows);
    demoted.emplace_back(at, std::move(L));
  }
  if (best.p < 1e-3) {
    report(P, blocks, best,
           window_shift_mm(M, M.X, r, window_columns(blocks, best.first, best.count, r.size())), D);
  } else if (!demoted.empty()) {
    // What a finding without a confident name took from the readings is still structure the
    // catalogue does not explain: reported where its local rival holds it, with the shifts
    // fitted in the finding's place.
    const auto& [at, L] = demoted.front();
    report(
        P, blocks, at,
        window_shift_mm(M, L.others, L.y_mm, window_columns(blocks, at.first, at.count, r.size())),
        D);
  }
}

}  // namespace rotacal::diagnosis_detail
