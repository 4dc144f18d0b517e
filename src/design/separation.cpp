// SPDX-License-Identifier: BSD-3-Clause
// The design engine (design/separation.hpp): the information algebra of a joint fit and the
// one search for the added measurement that separates two effects.
#include "rotacal/design/separation.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/design/format.hpp"

namespace rotacal {

// Covariance of an information matrix with the parameters the joint fit would hold fixed
// removed: those analyse_observability (core/least_squares.hpp) picks, one per combination
// that moving by plausible magnitudes changes chi-square by less than 1, on the white
// chi-square the fit tests (`white`: the information over the effective fraction, as the fit
// counts every reading). The covariance of the rest is the inverse of their information.
Inverted invert_information(const Eigen::MatrixXd& I, const Eigen::VectorXd& plausible,
                            double white) {
  const Eigen::Index p = I.rows();
  Inverted out;
  out.determined.assign(static_cast<std::size_t>(p), true);
  const Observability obs = analyse_observability_normal(I * white, plausible, 1.0);
  for (int j : obs.to_fix) out.determined[static_cast<std::size_t>(j)] = false;
  for (Eigen::Index j = 0; j < p; ++j)
    if (!(I(j, j) > 0.0)) out.determined[static_cast<std::size_t>(j)] = false;
  // What analyse_observability leaves exactly singular (one parameter fixed for two null
  // directions that share it): fix the parameter with the largest share of each remaining
  // null vector, one at a time, as a fit must.
  Eigen::MatrixXd cov_q;
  std::vector<Eigen::Index> idx;
  for (;;) {
    idx.clear();
    for (Eigen::Index j = 0; j < p; ++j)
      if (out.determined[static_cast<std::size_t>(j)]) idx.push_back(j);
    const Eigen::Index q = static_cast<Eigen::Index>(idx.size());
    Eigen::VectorXd dinv(q);
    for (Eigen::Index a = 0; a < q; ++a) dinv[a] = 1.0 / std::sqrt(I(idx[a], idx[a]));
    const Eigen::MatrixXd N = dinv.asDiagonal() * I(idx, idx) * dinv.asDiagonal();
    if (q == 0) {
      cov_q.resize(0, 0);
      break;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(N);
    const double lmax = std::max(es.eigenvalues().maxCoeff(), 1e-300);
    if (es.eigenvalues()[0] <= 1e-12 * lmax) {
      Eigen::Index worst = 0;
      es.eigenvectors().col(0).cwiseAbs().maxCoeff(&worst);
      out.determined[static_cast<std::size_t>(idx[worst])] = false;
      continue;
    }
    cov_q = dinv.asDiagonal() * es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() *
            es.eigenvectors().transpose() * dinv.asDiagonal();
    break;
  }
  const Eigen::Index q = static_cast<Eigen::Index>(idx.size());
  out.cov = Eigen::MatrixXd::Zero(p, p);
  for (Eigen::Index a = 0; a < q; ++a)
    for (Eigen::Index b = 0; b < q; ++b) out.cov(idx[a], idx[b]) = cov_q(a, b);
  out.sigma.resize(p);
  for (Eigen::Index j = 0; j < p; ++j)
    out.sigma[j] = out.determined[static_cast<std::size_t>(j)]
                       ? std::sqrt(std::max(out.cov(j, j), 0.0))
                       : std::numeric_limits<double>::infinity();
  return out;
}

// Largest canonical correlation between the estimates of the determined parameters of block a
// and of block b: the largest correlation of any combination of one block with any of the
// other (held parameters are fixed, as in the fit); 1 when no parameter of a block is
// determined.
double canonical_correlation(const Inverted& inv, const ParameterBlock& a,
                             const ParameterBlock& b) {
  std::vector<Eigen::Index> ia, ib;
  for (Eigen::Index j = a.offset; j < a.end(); ++j)
    if (inv.determined[static_cast<std::size_t>(j)]) ia.push_back(j);
  for (Eigen::Index j = b.offset; j < b.end(); ++j)
    if (inv.determined[static_cast<std::size_t>(j)]) ib.push_back(j);
  if (ia.empty() || ib.empty()) return 1.0;
  const Eigen::MatrixXd Caa = inv.cov(ia, ia), Cbb = inv.cov(ib, ib), Cab = inv.cov(ia, ib);
  const Eigen::LLT<Eigen::MatrixXd> la(Caa), lb(Cbb);
  if (la.info() != Eigen::Success || lb.info() != Eigen::Success) return 1.0;
  Eigen::MatrixXd M = la.matrixL().solve(Cab);
  M = lb.matrixL().solve(M.transpose()).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
  return std::min(1.0, svd.singularValues()[0]);
}

Eigen::MatrixXd in_layout(const Eigen::MatrixXd& J, const std::vector<ParameterBlock>& from,
                          const std::vector<ParameterBlock>& to, Eigen::Index p) {
  ROTACAL_ASSERT(from.size() == to.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(J.rows(), p);
  for (std::size_t k = 0; k < from.size(); ++k) {
    ROTACAL_ASSERT(from[k].size == to[k].size);
    to[k].columns(out) = from[k].columns(J);
  }
  return out;
}

double session_weight(double noise_um_option, const NoiseModel& noise, double fit_sigma_um,
                      const std::string& zero_noise, SeparationResult& D) {
  double sigma_um = noise_um_option > 0.0 ? noise_um_option : noise.sigma_um;
  if (!(sigma_um > 0.0)) sigma_um = fit_sigma_um;
  if (!(sigma_um > 0.0)) throw InvalidArgument(zero_noise);
  D.noise_um = sigma_um;
  if (noise.n > 0 && noise.effective_samples > 0.0)
    D.effective_per_reading = std::min(1.0, noise.effective_samples / static_cast<double>(noise.n));
  return D.effective_per_reading / (sigma_um * sigma_um * 1e-6);
}

SeparationProblem separation_problem(const Eigen::MatrixXd& Js, double w,
                                     const ParameterLayout& joint, const ParameterBlock& first,
                                     const ParameterBlock& second, double max_correlation,
                                     double max_added_time_s, const SeparationResult& D) {
  SeparationProblem S;
  S.session_information = Js.transpose() * Js * w;
  const std::vector<std::string> units = joint.units();
  S.plausible.resize(joint.size());
  for (Eigen::Index j = 0; j < joint.size(); ++j)
    S.plausible[j] = plausible_magnitude(units[static_cast<std::size_t>(j)]);
  S.white = 1.0 / D.effective_per_reading;
  S.first = first;
  S.second = second;
  S.max_correlation = max_correlation;
  S.max_added_time_s = max_added_time_s;
  return S;
}

bool separation_needed(const SeparationProblem& S, SeparationResult& D) {
  const Eigen::Index p0 = S.session_information.rows();
  const Inverted before = invert_information(S.session_information, S.plausible.head(p0), S.white);
  D.sigma_before = before.sigma;
  D.correlation_before = canonical_correlation(before, S.first, S.second);
  D.sigma_after = D.sigma_before;
  if (D.motion.same_motion) {
    D.verdict =
        "no test can separate " + D.effects[0] + " and " + D.effects[1] + ": " + D.motion.why;
    return false;
  }
  if (D.correlation_before < S.max_correlation) {
    D.already_separated = true;
    std::ostringstream v;
    v.precision(2);
    v << std::fixed << "the session alone separates " << D.effects[0] << " and " << D.effects[1]
      << " (correlation " << D.correlation_before << " < " << S.max_correlation
      << "): no added test is needed";
    D.verdict = v.str();
    return false;
  }
  return true;
}

SeparationChoice search_separation(const SeparationProblem& S,
                                   const std::vector<AddedInformation>& added) {
  const Eigen::Index p0 = S.session_information.rows();
  SeparationChoice best;
  double best_run = 0.0;
  Eigen::MatrixXd best_info;
  for (std::size_t k = 0; k < added.size(); ++k) {
    const AddedInformation& a = added[k];
    const Eigen::Index p = a.information.rows();
    Eigen::MatrixXd I0 = Eigen::MatrixXd::Zero(p, p);
    I0.topLeftCorner(p0, p0) = S.session_information;
    for (double rep = 1.0;
         a.duration_s * rep <= S.max_added_time_s * (1 + 1e-12) && (rep == 1.0 || a.repeatable);
         rep *= 2.0) {
      const Eigen::MatrixXd I = I0 + rep * a.information;
      const Inverted inv = invert_information(I, S.plausible.head(p), S.white);
      const double correlation = canonical_correlation(inv, S.first, S.second);
      bool determined = true;
      for (Eigen::Index j = S.first.offset; j < S.second.end(); ++j)
        determined = determined && inv.determined[static_cast<std::size_t>(j)];
      const double run = a.duration_s * rep;
      const auto take = [&] {
        best.index = k, best.repeats = rep, best.correlation = correlation,
        best.determined = determined;
        best_run = run;
        best_info = I;
      };
      if (correlation < S.max_correlation) {
        if (!best.found || run < best_run - 1e-9 ||
            (std::abs(run - best_run) <= 1e-9 && correlation < best.correlation)) {
          take();
          best.found = true;
        }
        break;
      }
      if (!best.found && (best.index == SeparationChoice::none || correlation < best.correlation))
        take();
    }
  }
  if (best.index != SeparationChoice::none)
    best.sigma_after =
        invert_information(best_info, S.plausible.head(best_info.rows()), S.white).sigma;
  return best;
}

void finish_separation(const SeparationProblem& S, const SeparationChoice& c,
                       const std::string& description, double run_s,
                       const std::vector<std::string>& added_names, const SeparationWording& w,
                       SeparationResult& D) {
  D.found = c.found;
  const double correlation =
      c.index == SeparationChoice::none ? D.correlation_before : c.correlation;
  if (c.index != SeparationChoice::none) {
    D.sigma_after = c.sigma_after;
    D.names.insert(D.names.end(), added_names.begin(), added_names.end());
  }
  std::ostringstream v;
  v.precision(2);
  v << std::fixed;
  if (D.found)
    v << "add " << description << ": " << fixed_text(run_s, 0)
      << " s; fitted with the session, the correlation of " << D.effects[0] << " and "
      << D.effects[1] << " goes from " << D.correlation_before << " to " << correlation;
  else
    v << "none of " << D.candidates_tried << " " << w.added << " within "
      << fixed_text(S.max_added_time_s, 0) << " s brings the correlation of " << D.effects[0]
      << " and " << D.effects[1] << " below " << S.max_correlation
      << (D.candidates_tried ? "; the closest is " + description + " (correlation " +
                                   fixed_text(correlation, 2) + ")" + w.closest_note
                             : std::string("; every candidate breaks a limit"));
  if (D.candidates_tried) {
    std::string held;
    for (Eigen::Index j = S.first.offset; j < S.second.end(); ++j)
      if (!std::isfinite(D.sigma_after[j]))
        held += (held.empty() ? "" : ", ") + D.names[static_cast<std::size_t>(j)];
    if (!held.empty())
      v << "; " << held << " remain undetermined (no reading" << w.seen_by
        << " sees them: the joint fit holds them at 0, and the correlation is that of the rest)";
  }
  D.verdict = v.str();
}

}  // namespace rotacal
