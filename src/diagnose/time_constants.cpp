// SPDX-License-Identifier: BSD-3-Clause
// A finding's time constant that the fit held (diagnosis.cpp, after the final refit): profiled
// over a grid, its uncertainty carried into the other parameters' sigmas (search.hpp).
#include <cmath>
#include <limits>

#include "search.hpp"

namespace rotacal::diagnosis_detail {

namespace {

struct ProfilePoint {
  double q = 0.0, chi2 = 0.0;
  Eigen::VectorXd x;      // the free parameters' steps, the amplitude last (its value, not a step)
  Eigen::VectorXd sigma;  // their 1-sigma under the treatment's whitening
};

// The model with the amplitude's column at q, linearised about the final fit in every other
// free parameter: min |W (r0 - d0 c0 + J_o dx + d c_q)|^2 over (dx, d).
ProfilePoint solve_at(const Eigen::MatrixXd& Jo_w, const Eigen::VectorXd& base_w,
                      const Eigen::VectorXd& col, const NoiseTreatment& t, double q) {
  Eigen::MatrixXd A(Jo_w.rows(), Jo_w.cols() + 1);
  A.leftCols(Jo_w.cols()) = Jo_w;
  A.col(Jo_w.cols()) = t.whiten(col);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  ProfilePoint p;
  p.q = q;
  p.x = qr.solve(-base_w);
  p.chi2 = (base_w + A * p.x).squaredNorm();
  const Eigen::MatrixXd cov =
      (A.transpose() * A).ldlt().solve(Eigen::MatrixXd::Identity(A.cols(), A.cols()));
  p.sigma = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  return p;
}

}  // namespace

// Scored with its time-constant column zero (the shift is d (1 - exp(-t / tau)), d = 0), a
// warm-up is one shape, that of tau = 300 s; a session's warm-up of another tau leaves the
// difference, which the candidate's own noise model then takes for slow noise and whitens
// away (thermal_warmup_Z on the probe in AR(1) 0.9 noise at 10x the half-detection amplitude:
// 'nothing' in 13 of 20 sessions, bench/diagnosis_confusion.py; the Z shift of a touch follows
// the pose's five approach directions, a period of five touches that an AR(6) follows). The
// column of q = ln(tau / 300 s) is filled with the shift's derivative in q at a unit amplitude,
// geometry_i d(factor)/dq = -(t / tau) exp(-t / tau) per reading (the geometry from the
// amplitude's column), so the candidate spans the warm-ups near tau = 300 s and is scored with
// both parameters (and their BIC penalty). The fits free tau themselves
// (core/time_constant_fit.hpp).
void with_time_constant_tangent(const DiagnosisProblem& P, const Effect& candidate,
                                Eigen::MatrixXd& J) {
  const std::vector<double>& times = P.times();
  if (candidate.kind != EffectKind::thermal_warmup || J.cols() != 2 ||
      static_cast<Eigen::Index>(times.size()) != J.rows() || J.col(1).squaredNorm() > 0.0)
    return;
  for (Eigen::Index i = 0; i < J.rows(); ++i) {
    const double t = times[static_cast<std::size_t>(i)], g = thermal_warmup_factor(t, 0.0);
    J(i, 1) = g > 1e-12 ? J(i, 0) / g * (-(t / 300.0) * std::exp(-t / 300.0)) : 0.0;
  }
}

// A thermal_warmup's tau moves nothing while its amplitude is 0, where every fit starts, so the
// probe's and the R-test's fits hold it at 300 s and report it unobservable; the amplitude at a
// held tau is then biased where the session's tau differs (tau 125 s in a 375 s probe session:
// 2-sigma coverage of d 1-10 %, bench/diagnosis_confusion.py). Profiled instead: the final
// model's residual under the treatment `t` (sigmas scaled by `scale` after) over
// q = ln(tau / 300 s) in [-4, 3] (5 s to 6000 s),
// linearised about the final fit in every other parameter (the amplitude enters linearly at a
// given tau, the others barely move with it). The best q is taken; the set of q within one
// (scaled) chi-square unit of it is tau's 1-sigma interval, and every free parameter's sigma
// gets the half of its change across that interval in quadrature, so a tau the data leave open
// widens the amplitude's sigma rather than leaving a confidently wrong amplitude. Tau is
// reported (q +- half the interval) only where the interval closes inside the grid; the
// amplitude only where it stays finite over it. Nothing changes where the fit freed tau
// (the ballbar's two-stage fit) or the times are not one per residual. Updates D.final_fit
// (values, sigmas before the caller's `scale`, residuals); the caller reads the findings' from it.
void profile_time_constants(const DiagnosisProblem& P, const NoiseTreatment& t, double scale,
                            Diagnosis& D) {
  ModelFit& F = D.final_fit;
  const std::vector<double>& times = P.times();
  if (static_cast<Eigen::Index>(times.size()) != F.residuals.size()) return;
  for (Finding& finding : D.findings) {
    if (finding.effect.kind != EffectKind::thermal_warmup) continue;
    const std::string id = finding.effect.id();
    Eigen::Index jd = -1, jq = -1;
    for (std::size_t j = 0; j < F.parameters.size(); ++j) {
      if (F.parameters[j].name == id + ".d") jd = static_cast<Eigen::Index>(j);
      if (F.parameters[j].name == id + ".ln_tau_300s") jq = static_cast<Eigen::Index>(j);
    }
    if (jd < 0 || jq < 0 || !F.parameters[static_cast<std::size_t>(jd)].observable) continue;
    if (F.jacobian.col(jq).squaredNorm() > 0.0 &&
        F.parameters[static_cast<std::size_t>(jq)].observable)
      continue;
    const double q0 = F.parameters[static_cast<std::size_t>(jq)].value;
    const double d0 = F.parameters[static_cast<std::size_t>(jd)].value;
    const Eigen::VectorXd c0 = F.jacobian.col(jd);
    // The column's geometry per reading, c0_i / factor(t_i, q0) (0 where t_i = 0: no shift yet).
    Eigen::VectorXd geometry = Eigen::VectorXd::Zero(c0.size());
    for (Eigen::Index i = 0; i < c0.size(); ++i) {
      const double g = thermal_warmup_factor(times[static_cast<std::size_t>(i)], q0);
      if (g > 1e-12) geometry[i] = c0[i] / g;
    }
    const auto column_at = [&](double q) {
      Eigen::VectorXd c(c0.size());
      for (Eigen::Index i = 0; i < c.size(); ++i)
        c[i] = geometry[i] * thermal_warmup_factor(times[static_cast<std::size_t>(i)], q);
      return c;
    };
    std::vector<Eigen::Index> others;
    for (Eigen::Index j = 0; j < F.jacobian.cols(); ++j)
      if (j != jd && j != jq && F.jacobian.col(j).squaredNorm() > 0.0) others.push_back(j);
    Eigen::MatrixXd Jo(F.jacobian.rows(), static_cast<Eigen::Index>(others.size()));
    for (std::size_t k = 0; k < others.size(); ++k)
      Jo.col(static_cast<Eigen::Index>(k)) = F.jacobian.col(others[k]);
    const Eigen::MatrixXd Jo_w = t.whiten(Jo);
    const Eigen::VectorXd base_w = t.whiten(Eigen::MatrixXd(F.residuals - d0 * c0));
    const Eigen::Index last = Jo_w.cols();

    const ProfilePoint at0 = solve_at(Jo_w, base_w, c0, t, q0);
    // The reported sigmas over the linear ones at q0: the treatment's scale (chi-square per dof
    // above 1, hidden levels), the chi-square unit of tau's interval in the same scale.
    const double reported_d = F.parameters[static_cast<std::size_t>(jd)].std;
    if (!(at0.sigma[last] > 0.0) || !(reported_d > 0.0)) continue;
    const double k = scale * reported_d / at0.sigma[last];
    std::vector<ProfilePoint> grid;
    for (int s = -40; s <= 30; ++s)
      grid.push_back(solve_at(Jo_w, base_w, column_at(0.1 * s), t, 0.1 * s));
    std::size_t best = 0;
    for (std::size_t s = 1; s < grid.size(); ++s)
      if (grid[s].chi2 < grid[best].chi2) best = s;
    if (at0.chi2 <= grid[best].chi2) continue;  // the held tau is already the best
    const double limit = grid[best].chi2 + k * k;
    std::size_t lo = best, hi = best;
    while (lo > 0 && grid[lo - 1].chi2 <= limit) --lo;
    while (hi + 1 < grid.size() && grid[hi + 1].chi2 <= limit) ++hi;
    const bool closed = lo > 0 && hi + 1 < grid.size();
    const ProfilePoint& b = grid[best];
    // Every free parameter: value at the best q, sigma with its half change across the interval.
    const auto update = [&](std::size_t j, Eigen::Index col) {
      ParameterEstimate& p = F.parameters[j];
      double vmin = std::numeric_limits<double>::infinity(), vmax = -vmin;
      for (std::size_t s = lo; s <= hi; ++s) {
        vmin = std::min(vmin, grid[s].x[col]);
        vmax = std::max(vmax, grid[s].x[col]);
      }
      const double half = 0.5 * (vmax - vmin);
      const double scaled = at0.sigma[col] > 0.0 ? p.std * b.sigma[col] / at0.sigma[col] : p.std;
      p.value = col == last ? b.x[col] : p.value + b.x[col];
      p.std = std::sqrt(scaled * scaled + (half / scale) * (half / scale));
    };
    for (std::size_t kcol = 0; kcol < others.size(); ++kcol)
      update(static_cast<std::size_t>(others[kcol]), static_cast<Eigen::Index>(kcol));
    update(static_cast<std::size_t>(jd), last);
    // A tau open towards long times is a drift: d grows with tau without bound there.
    if (hi + 1 >= grid.size()) F.parameters[static_cast<std::size_t>(jd)].observable = false;
    ParameterEstimate& pq = F.parameters[static_cast<std::size_t>(jq)];
    pq.value = b.q;
    pq.observable = closed;
    pq.std = closed ? 0.5 * (grid[hi].q - grid[lo].q) + 0.05 : 0.0;  // + half a grid step
    const Eigen::VectorXd step = Jo * b.x.head(last) + b.x[last] * column_at(b.q) - d0 * c0;
    F.residuals += step;
  }
}

}  // namespace rotacal::diagnosis_detail
