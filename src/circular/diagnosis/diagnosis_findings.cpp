// SPDX-License-Identifier: BSD-3-Clause
// The final model of the circular-test diagnosis: GLS under the noise of its residuals, each
// finding's parameters with 1-sigma (linear ones from the whitened Jacobian, nonlinear ones
// from their profile, whose spread is carried into the linear ones), its gain, and why each
// entry left out stays unobservable.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "diagnosis_detail.hpp"
#include "rotacal/core/stats.hpp"

namespace rotacal::circular_detail {

// Final model: noise from its residuals, GLS; linear parameters' 1-sigma from the whitened
// Jacobian, the nonlinear ones' from the curvature of the profile (delta chi-square 1).
void CircularSearch::final_model() {
  offsets.clear();
  M = model_columns(R, B, chosen, o_.screw_pitch, &offsets);
  fit = gls(R, M, R.y, W);
  if (o_.model_noise) {
    out.noise = noise_of(R, fit.r_mm);
    W.set(out.noise);
    fit = gls(R, M, R.y, W);
  } else {
    out.noise = noise_of(R, fit.r_mm);
  }
  out.noise_whitened = W.w != nullptr;
  out.residuals_mm = fit.r_mm;
  out.final_rms_um = rms_um(fit.r_mm);
  const Eigen::MatrixXd& Jfull = M;
  const Eigen::MatrixXd Jw = W(Jfull);
  int n_nonlinear = 0;
  for (const Chosen& c : chosen) n_nonlinear += nonlinear_params(c.effect);
  final_dof = static_cast<double>(R.n) - static_cast<double>(Jw.cols()) - n_nonlinear;
  s2 = fit.rss_w / final_dof;
  // Column-scaled inverse of the normal matrix: the baseline's columns are O(1), the effects'
  // up to O(R^2); scaling keeps the inverse accurate.
  col_scale = Jw.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < col_scale.size(); ++j)
    if (!(col_scale[j] > 0.0)) col_scale[j] = 1.0;
  const Eigen::MatrixXd Js = Jw * col_scale.cwiseInverse().asDiagonal();
  Ninv = (Js.transpose() * Js).ldlt().solve(Eigen::MatrixXd::Identity(Js.cols(), Js.cols()));
}

// 1-sigma of a profiled parameter: rss_w(x) ~ rss_w(x0) + f'' (x - x0)^2 / 2, chi-square
// rss_w / s2, so sigma = sqrt(2 s2 / f''); not determined (observable false) if f'' <= 0.
std::pair<double, bool> CircularSearch::profile_std(double* field, double h, bool log_scale) {
  const double x0 = *field;
  const auto at = [&](double x) { return rss_with(field, log_scale ? std::exp(x) : x); };
  const double c0 = log_scale ? std::log(x0) : x0;
  const double lo = log_scale ? c0 - h : std::max(0.0, c0 - h), hi = lo + 2.0 * h;
  const double mid = 0.5 * (lo + hi);
  const double f2 = (at(hi) - 2.0 * at(mid) + at(lo)) / (h * h);
  if (!(f2 > 0.0)) return {std::numeric_limits<double>::quiet_NaN(), false};
  const double sd = std::sqrt(2.0 * s2 / f2);
  return {log_scale ? sd * x0 : sd, true};
}

// The model's coefficients with entry k's nonlinear parameters at (tau, delay), refitted.
Eigen::VectorXd CircularSearch::beta_at(std::size_t k, double tau, double delay) {
  const Chosen keep = chosen[k];
  chosen[k].tau = tau;
  chosen[k].delay = delay;
  const Eigen::VectorXd b = gls(R, model_columns(R, B, chosen, o_.screw_pitch), R.y, W).beta;
  chosen[k] = keep;
  return b;
}

void CircularSearch::add_findings() {
  const auto std_of = [&](Eigen::Index j) {
    return std::sqrt(std::max(Ninv(j, j), 0.0) * s2) / col_scale[j];
  };
  const std::vector<int> fold = run_folds(R, o_.cv_blocks);
  const double cv_all = cv_rms_um(R, M, R.y, fold, o_.cv_blocks);
  // The nonlinear parameters' uncertainty moves the linear ones (a spike's height trades with
  // its delay and tau): each linear parameter's variance gets the square of its half change
  // across the nonlinear parameter's range (tau: +-1 sigma), refitted.
  std::vector<std::pair<double, bool>> tau_sd(chosen.size(), {0.0, false});
  Eigen::VectorXd extra_var = Eigen::VectorXd::Zero(M.cols());
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const Chosen c = chosen[k];
    if (c.effect.kind == CircularEffectKind::reversal_spike) {
      tau_sd[k] = profile_std(&chosen[k].tau, 0.05, true);
      if (tau_sd[k].second && tau_sd[k].first < c.tau) {
        const Eigen::VectorXd d = 0.5 * (beta_at(k, c.tau + tau_sd[k].first, c.delay) -
                                         beta_at(k, c.tau - tau_sd[k].first, c.delay));
        extra_var += d.cwiseAbs2();
      }
    }
    // A delay: between the ends of its delta-chi-square-1 range (readings inside it; the model
    // jumps where a step crosses a reading, so +-1 sigma could land beyond a stair's edge).
    if (nonlinear_params(c.effect) && c.delay_range.second > c.delay_range.first) {
      const Eigen::VectorXd d =
          0.5 * (beta_at(k, c.tau, c.delay_range.second) - beta_at(k, c.tau, c.delay_range.first));
      extra_var += d.cwiseAbs2();
    }
  }
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    CircularFinding f;
    f.effect = chosen[k].effect.id();
    f.cause = chosen[k].effect.cause();
    const auto names = chosen[k].effect.param_names();
    const auto units = chosen[k].effect.param_units();
    for (std::size_t j = 0; j < names.size(); ++j) {
      ParameterEstimate p;
      p.name = f.effect + "." + names[j];
      p.unit = units[j];
      if (names[j] == "tau") {
        p.value = chosen[k].tau;
        p.std = tau_sd[k].first;
        p.observable = tau_sd[k].second;
      } else if (names[j] == "delay") {
        p.value = chosen[k].delay;
        p.std = chosen[k].delay_sd;
      } else {
        const Eigen::Index c = offsets[k] + static_cast<Eigen::Index>(j);
        p.value = fit.beta[c];
        p.std = std::sqrt(std_of(c) * std_of(c) + extra_var[c]);
      }
      f.parameters.push_back(p);
    }
    // Gain: the final model without this entry, refitted under the same noise model.
    std::vector<Chosen> others = chosen;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
    const Eigen::MatrixXd Mo = model_columns(R, B, others, o_.screw_pitch);
    const Gls without = gls(R, Mo, R.y, W);
    const double n = static_cast<double>(R.n);
    const int kk = static_cast<int>(M.cols() - Mo.cols()) + nonlinear_params(chosen[k].effect);
    f.gain.rms_before_um = rms_um(without.r_mm);
    f.gain.rms_after_um = out.final_rms_um;
    f.gain.delta_bic = n * std::log(std::max(fit.rss_w, 1e-300) / without.rss_w) + kk * std::log(n);
    const double F = ((without.rss_w - fit.rss_w) / kk) / (fit.rss_w / final_dof);
    f.gain.f_pvalue = stats::f_sf(std::max(F, 0.0), kk, final_dof);
    f.gain.cv_rms_before_um = cv_rms_um(R, Mo, R.y, fold, o_.cv_blocks);
    f.gain.cv_rms_after_um = cv_all;
    out.findings.push_back(std::move(f));
  }
}

void CircularSearch::explain_unobservable() {
  for (const std::string& id : invisible)
    out.unobservable.push_back(
        {id, "at plausible sizes it changes these readings by less than 5 sigma in all"});
  // Entries left out that the final model makes invisible: name what absorbs them.
  const ModelBasis Qb(R, W(B));
  for (const CircularEffect& e : cands) {
    if (!absorbed.count(e.id())) continue;
    const Eigen::MatrixXd Jc = W(cols[e.id()].front().J);
    Scored vs_base =
        score_one(e, Jc, Qb, Eigen::VectorXd::Zero(Jc.rows()), Qb.rank(), o_.min_visible_chi2);
    std::string why;
    if (!vs_base.visible) {
      why = "the centre offset and radius of each run absorb its signature in these runs";
    } else {
      std::string by;
      for (const Chosen& c : chosen) {
        std::vector<Chosen> one = {c};
        const ModelBasis Q1(R, W(model_columns(R, B, one, o_.screw_pitch)));
        if (!score_one(e, Jc, Q1, Eigen::VectorXd::Zero(Jc.rows()), Q1.rank(), o_.min_visible_chi2)
                 .visible)
          by += (by.empty() ? "" : ", ") + c.effect.id();
      }
      why = "in these runs its signature is that of " +
            (by.empty() ? std::string("the findings together") : by);
      const bool sq_servo = (e.kind == CircularEffectKind::squareness ||
                             e.kind == CircularEffectKind::servo_mismatch);
      if (sq_servo && (R.directions.size() < 2))
        why += ": a cw and a ccw run (or two feeds) separate squareness from servo mismatch";
    }
    out.unobservable.push_back({e.id(), why});
  }
}

}  // namespace rotacal::circular_detail
