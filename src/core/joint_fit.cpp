// SPDX-License-Identifier: BSD-3-Clause
// The joint-fit driver: observability, a dense Gauss-Newton solve with step control,
// covariance and estimates for every fit in rotacal.
//
// Why not Ceres here: the fits have 11 to ~70 unknowns and up to 10^6 scalar residuals,
// with every residual depending on (nearly) every unknown, so the problem is one dense block.
// Built per sample, Ceres spent its time in per-block bookkeeping: the ballbar fit of
// ballbar_ac_table2.csv (1,804 residual blocks) took 24 ms and the R-test joint fit 202 ms
// (issue 14), 90,000 ballbar samples 1.36 s and 189 MB. A dense normal-equation solve over a
// Jacobian evaluated in one batch costs n p^2 flops (0.2 Mflop for table2) and needs one n x p
// array; the Jets of the model are then the whole cost (~0.8 us a sample for the ballbar's 11
// unknowns). The models are nearly linear over um-sized errors, so the Jacobian is kept while
// it still contracts the step (chord iteration, residuals only), and on a long session the
// first steps are taken on every k-th sample (k ~ n / 32p), so that one full Jacobian,
// evaluated near the solution, serves the last step and the covariance. Measured on the 2-core
// machine (wall, in a loop): table2 0.24-0.34 ms with the ballbar's analytic Jacobian evaluated
// four samples at a time (0.4-0.5 ms a sample at a time; a full evaluation from the start point
// instead of the subsample start: about twice that), R-test 2 x 84 poses 5.1 ms, 600,000
// ballbar samples 0.21-0.25 s and 221-227 MB peak for the process.
#include "rotacal/core/joint_fit.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "rotacal/core/yield_convention.hpp"

namespace rotacal {

namespace {

// J^T J (p x p) of a weighted Jacobian: gram_matrix (least_squares.hpp), named here as the
// driver reads it.
Eigen::MatrixXd gram(const Eigen::MatrixXd& J) { return gram_matrix(J); }

// Normal equations of the free columns, column-normalised for conditioning, of the weighted
// Jacobian scale * J (scale 1/sigma for white noise: J itself need not be scaled and back). With
// every column free the normal matrix is gram(Jw) scale^2, taken from `G` when the caller has
// computed it already.
struct NormalEquations {
  Eigen::VectorXd D;        // column norms of the weighted Jacobian (free columns)
  Eigen::MatrixXd A;        // (J D^-1)^T (J D^-1)
  Eigen::MatrixXd Ainv;     // A^-1: covariance in normalised coordinates (chi2 units)
  Eigen::VectorXd sigma_y;  // sqrt(diag(A^-1)): 1 sigma in normalised coordinates
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
};

NormalEquations normal_equations(const Eigen::MatrixXd& Jw, double scale,
                                 const std::vector<Eigen::Index>& idx,
                                 const Eigen::MatrixXd* G = nullptr) {
  const Eigen::Index q = static_cast<Eigen::Index>(idx.size());
  NormalEquations ne;
  ne.A.setZero(q, q);
  if (q == Jw.cols()) {  // all columns free
    ne.A = G ? *G : Eigen::MatrixXd(gram(Jw) * (scale * scale));
  } else {
    for (Eigen::Index a = 0; a < q; ++a)
      for (Eigen::Index b = a; b < q; ++b)
        ne.A(a, b) = ne.A(b, a) =
            Jw.col(idx[static_cast<std::size_t>(a)]).dot(Jw.col(idx[static_cast<std::size_t>(b)])) *
            (scale * scale);
  }
  ne.D = ne.A.diagonal().cwiseSqrt();
  for (Eigen::Index a = 0; a < q; ++a)
    if (!(ne.D[a] > 0.0)) ne.D[a] = 1.0;
  ne.A = ne.D.cwiseInverse().asDiagonal() * ne.A * ne.D.cwiseInverse().asDiagonal();
  ne.ldlt.compute(ne.A);
  ne.Ainv = ne.ldlt.solve(Eigen::MatrixXd::Identity(q, q));
  ne.sigma_y = ne.Ainv.diagonal().cwiseMax(0.0).cwiseSqrt();
  return ne;
}

// Largest |dx_j| in units of parameter j's 1 sigma (chi2 units).
double max_sigma_step(const NormalEquations& ne, const Eigen::VectorXd& dx_free) {
  double m = 0.0;
  for (Eigen::Index a = 0; a < dx_free.size(); ++a)
    if (ne.sigma_y[a] > 0.0) m = std::max(m, std::abs(dx_free[a] * ne.D[a]) / ne.sigma_y[a]);
  return m;
}

}  // namespace

namespace {

// Reports the solution under the yield convention (core/yield_convention.hpp) where a null
// direction moves a parameter with FitParameter::yields: values and covariance are mapped,
// the null directions it resolves are no longer listed, `observable` is updated.
void apply_yield_convention(const std::vector<FitParameter>& params,
                            const std::vector<int>& analysed, const Eigen::VectorXd& scales,
                            JointFitOutcome& out, std::vector<bool>& observable) {
  std::vector<bool> yields;
  for (int j : analysed) yields.push_back(params[static_cast<std::size_t>(j)].yields);
  std::vector<bool> obs_a = out.observability.observable;
  const Eigen::MatrixXd Ma = yield_convention(out.observability, yields, scales, &obs_a);
  if (Ma.size() == 0) return;
  const Eigen::Index p = out.values.size();
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(p, p);
  for (std::size_t a = 0; a < analysed.size(); ++a)
    for (std::size_t b = 0; b < analysed.size(); ++b)
      M(analysed[a], analysed[b]) = Ma(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  out.values = M * out.values;
  out.covariance = M * out.covariance * M.transpose();
  out.convention = std::move(M);
  // A parameter left with a 1-sigma below 1e-6 of its plausible magnitude is fixed by the
  // convention, not by the data.
  for (std::size_t k = 0; k < analysed.size(); ++k) {
    const Eigen::Index j = analysed[k];
    observable[static_cast<std::size_t>(j)] =
        obs_a[k] && std::sqrt(std::max(0.0, out.covariance(j, j))) >
                        1e-6 * scales[static_cast<Eigen::Index>(k)];
  }
  // A null direction the convention resolves no longer moves the reported solution: it is a
  // direction of the old, held convention, and is dropped from the words.
  std::vector<std::string> kept;
  for (std::size_t k = 0; k < out.observability.null_space.size(); ++k) {
    const Eigen::VectorXd& v = out.observability.null_space[k];
    const Eigen::VectorXd moved = Ma * v;  // zero where the convention fixes this direction
    if (moved.cwiseQuotient(scales).norm() > 0.5 * v.cwiseQuotient(scales).norm())
      kept.push_back(out.unobservable[k]);
  }
  out.unobservable = std::move(kept);
}

}  // namespace

namespace {

// What every stage of solve_joint reads: the model, its parameters, the settings and the
// weighting they imply.
struct JointProblem {
  const ResidualModel& model;
  const std::vector<FitParameter>& params;
  const JointFitSettings& s;
  int p = 0;
  Eigen::Index n = 0;
  double inv_sigma = 1.0;  // 1 / sigma once, applied as a product to residual vectors
  // The full Jacobian Jw is stored as J_weighted / jw_scale: whitened in place under a
  // whitener, left as J under white noise (1/sigma goes into its products instead, which saves
  // scaling the n x p array and scaling it back for the caller).
  double jw_scale = 1.0;
  std::vector<int> analysed;  // the parameters not held

  JointProblem(const ResidualModel& m, const std::vector<FitParameter>& ps,
               const JointFitSettings& settings)
      : model(m), params(ps), s(settings) {
    p = static_cast<int>(params.size());
    if (model.num_parameters() != p)
      throw InvalidArgument("solve_joint: the model has " + std::to_string(model.num_parameters()) +
                            " parameters but " + std::to_string(p) + " were described");
    n = model.num_residuals();
    if (s.whitener && s.whitener->size() != n)
      throw InvalidArgument("solve_joint: whitener was built for " +
                            std::to_string(s.whitener->size()) + " residuals, the fit has " +
                            std::to_string(n));
    if (!(s.sigma > 0.0) || !std::isfinite(s.sigma))
      throw InvalidArgument("solve_joint: sigma must be finite and > 0");
    inv_sigma = 1.0 / s.sigma;
    jw_scale = s.whitener ? 1.0 : inv_sigma;
    for (int j = 0; j < p; ++j)
      if (!params[static_cast<std::size_t>(j)].held) analysed.push_back(j);
  }
  void weigh(Eigen::VectorXd& r) const {
    if (s.whitener)
      s.whitener->apply(r);
    else
      r *= inv_sigma;
  }
  void weigh_jacobian(Eigen::MatrixXd& J) const {
    if (s.whitener) s.whitener->apply(J);
  }
  Eigen::VectorXd scales() const {
    Eigen::VectorXd sc(static_cast<Eigen::Index>(analysed.size()));
    for (std::size_t k = 0; k < analysed.size(); ++k) {
      const FitParameter& fp = params[static_cast<std::size_t>(analysed[k])];
      sc[static_cast<Eigen::Index>(k)] = fp.scale > 0.0 ? fp.scale : plausible_magnitude(fp.unit);
    }
    return sc;
  }
  // Observability of the analysed parameters from a Gram matrix; per parameter: free or not.
  std::vector<bool> free_set(const Eigen::MatrixXd& G, Observability* obs) const {
    const Eigen::Index m = static_cast<Eigen::Index>(analysed.size());
    Eigen::MatrixXd Ga(m, m);
    for (Eigen::Index a = 0; a < m; ++a)
      for (Eigen::Index b = 0; b < m; ++b)
        Ga(a, b) = G(analysed[static_cast<std::size_t>(a)], analysed[static_cast<std::size_t>(b)]);
    *obs = analyse_observability_normal(Ga, scales(), s.observability_min_chi2);
    std::vector<bool> free(static_cast<std::size_t>(p), false);
    for (int j : analysed) free[static_cast<std::size_t>(j)] = true;
    for (int k : obs->to_fix)
      free[static_cast<std::size_t>(analysed[static_cast<std::size_t>(k)])] = false;
    return free;
  }
};

std::vector<Eigen::Index> free_indices(const std::vector<bool>& free) {
  std::vector<Eigen::Index> idx;
  for (std::size_t j = 0; j < free.size(); ++j)
    if (free[j]) idx.push_back(static_cast<Eigen::Index>(j));
  return idx;
}

// A start on every k-th sample for long sessions without a whitener (the whitener acts on
// the whole residual vector): Gauss-Newton there is cheap and lands within ~sqrt(k) sigma of
// the solution, so that the full Jacobian is evaluated where it is used. Moves x; returns the
// free set the subsample judged (empty: no subsample start).
std::vector<bool> subsample_start(const JointProblem& pr, Eigen::VectorXd& x, FitSummary& sum) {
  const Eigen::Index items = pr.model.num_items();
  const Eigen::Index stride = items / std::max<Eigen::Index>(32 * std::max(pr.p, 8), 1);
  std::vector<bool> free_subset;
  if (pr.s.whitener || stride < 2) return free_subset;
  Eigen::VectorXd rs, rs_t;
  Eigen::MatrixXd Js;
  if (!(pr.model.evaluate_subset(x, stride, rs, &Js) && rs.allFinite() && Js.allFinite()))
    return free_subset;
  rs *= pr.inv_sigma;
  Js *= pr.inv_sigma;
  Observability obs;
  const Eigen::MatrixXd Gs = gram(Js);
  // Information of the whole session ~ stride times the subsample's.
  free_subset = pr.free_set(Gs * static_cast<double>(stride), &obs);
  const std::vector<Eigen::Index> idx = free_indices(free_subset);
  NormalEquations ne = normal_equations(Js, 1.0, idx, &Gs);
  // Only where the subsample pins every free parameter to 1 % of its plausible size: a
  // weakly determined direction would wander there (the problem is not linear over that
  // range), and where the full analysis and solve start would then matter.
  const Eigen::VectorXd sc = pr.scales();
  for (std::size_t a = 0; a < idx.size(); ++a) {
    const auto k = std::find(pr.analysed.begin(), pr.analysed.end(), static_cast<int>(idx[a])) -
                   pr.analysed.begin();
    const double sigma_param =
        ne.sigma_y[static_cast<Eigen::Index>(a)] / ne.D[static_cast<Eigen::Index>(a)];
    if (!(sigma_param < 0.01 * sc[k])) return {};
  }
  double cost = rs.squaredNorm();
  for (int it = 0; it < 20 && !idx.empty(); ++it) {
    Eigen::VectorXd g(static_cast<Eigen::Index>(idx.size()));
    for (Eigen::Index a = 0; a < g.size(); ++a)
      g[a] = Js.col(idx[static_cast<std::size_t>(a)]).dot(rs) / ne.D[a];
    const Eigen::VectorXd dx = ne.D.cwiseInverse().cwiseProduct(-ne.ldlt.solve(g));
    Eigen::VectorXd xt = x;
    for (Eigen::Index a = 0; a < dx.size(); ++a) xt[idx[static_cast<std::size_t>(a)]] += dx[a];
    pr.model.evaluate_subset(xt, stride, rs_t, nullptr);
    ++sum.residual_evaluations;
    rs_t *= pr.inv_sigma;
    const double cost_t = rs_t.squaredNorm();
    if (!std::isfinite(cost_t) || cost_t > cost) break;
    x = xt, rs.swap(rs_t), cost = cost_t;
    if (max_sigma_step(ne, dx) < 1e-2) break;  // well inside the full fit's basin
  }
  return free_subset;
}

// Residuals and Jacobian at x, weighted, and their Gram matrix (observability and the normal
// equations both start from it).
struct FullEvaluation {
  Eigen::VectorXd r, rw;
  Eigen::MatrixXd Jw, G;

  explicit FullEvaluation(const JointProblem& pr) : r(pr.n), rw(pr.n), Jw(pr.n, pr.p) {}
  void evaluate(const JointProblem& pr, const Eigen::VectorXd& x, FitSummary& sum) {
    pr.model.evaluate(x, r, &Jw);
    ++sum.jacobian_evaluations;
    for (Eigen::Index i = 0; i < pr.n; ++i)
      if (!std::isfinite(r[i]))
        throw InvalidArgument("solve_joint: residual " + std::to_string(i) +
                              " is not finite at the start point");
    rw = r;
    pr.weigh(rw);
    pr.weigh_jacobian(Jw);
    G = gram(Jw) * (pr.jw_scale * pr.jw_scale);
  }
};

// Observability on the full Jacobian: fix one parameter per invisible combination. The
// models are nearly linear over um-sized errors, so it matters little where; but when the
// subsample judged otherwise, a direction is near the threshold and the analysis is redone
// at the start point x0, where every fit makes it. Fills out.free, out.observability and
// out.unobservable; returns each parameter's observability.
std::vector<bool> analyse_full(const JointProblem& pr, const std::vector<bool>& free_subset,
                               const Eigen::VectorXd& x0, Eigen::VectorXd& x, FullEvaluation& ev,
                               JointFitOutcome& out) {
  out.free = pr.free_set(ev.G, &out.observability);
  if (!free_subset.empty() && free_subset != out.free) {
    x = x0;
    ev.evaluate(pr, x, out.summary);
    out.free = pr.free_set(ev.G, &out.observability);
  }
  std::vector<std::string> names, units;
  for (int j : pr.analysed)
    names.push_back(pr.params[static_cast<std::size_t>(j)].name),
        units.push_back(pr.params[static_cast<std::size_t>(j)].unit);
  for (std::size_t k = 0; k < out.observability.null_space.size(); ++k)
    out.unobservable.push_back(out.observability.describe(static_cast<int>(k), names, units));
  std::vector<bool> observable(static_cast<std::size_t>(pr.p), false);
  for (std::size_t k = 0; k < pr.analysed.size(); ++k)
    observable[static_cast<std::size_t>(pr.analysed[k])] = out.observability.observable[k];
  return observable;
}

// Gauss-Newton: the Jacobian is reused (chord steps, residuals only) while the step keeps
// shrinking by 10x per iteration, and refreshed when a step does not reduce the cost or
// contracts slowly. At convergence a stale Jacobian moves the solution by about
// (J_ref - J)^T r: relative change of J (~ the contraction ratio rho of the chord steps)
// times sqrt(chi2) sigma at most; accepted below stale_jacobian_sigma, else refreshed. Moves x
// and ev to the solution; returns the last normal equations (Jacobian within 0.01 sigma of
// the solution) and sets `cost`.
NormalEquations gauss_newton(const JointProblem& pr, const std::vector<Eigen::Index>& idx,
                             Eigen::VectorXd& x, FullEvaluation& ev, FitSummary& sum,
                             double& cost) {
  const JointFitSettings& s = pr.s;
  const Eigen::Index q = static_cast<Eigen::Index>(idx.size());
  NormalEquations ne = normal_equations(ev.Jw, pr.jw_scale, idx, &ev.G);
  bool at_J = true;
  cost = ev.rw.squaredNorm();
  double lambda = 0.0, last_step = -1.0;
  // Largest contraction ratio of chord steps since the last refresh, from steps above 1e-3
  // sigma (below that the ratio measures round-off, not the Jacobian); 0: none measured yet.
  double rho = 0.0;
  Eigen::VectorXd r_t(pr.n), rw_t(pr.n), x_t(pr.p);
  const auto refresh = [&] {
    pr.model.evaluate(x, ev.r, &ev.Jw);
    ++sum.jacobian_evaluations;
    ev.rw = ev.r;
    pr.weigh(ev.rw);
    pr.weigh_jacobian(ev.Jw);
    ne = normal_equations(ev.Jw, pr.jw_scale, idx);
    at_J = true;
    cost = ev.rw.squaredNorm();
    last_step = -1.0;
    rho = 0.0;
  };
  sum.message = "reached max_iterations";
  while (sum.iterations < s.max_iterations) {
    Eigen::VectorXd g(q);
    for (Eigen::Index a = 0; a < q; ++a)
      g[a] = ev.Jw.col(idx[static_cast<std::size_t>(a)]).dot(ev.rw) * pr.jw_scale / ne.D[a];
    Eigen::VectorXd y;
    if (lambda > 0.0) {
      Eigen::MatrixXd Al = ne.A;
      Al.diagonal() *= 1.0 + lambda;
      y = -Al.ldlt().solve(g);
    } else {
      y = -ne.ldlt.solve(g);
    }
    const Eigen::VectorXd dx = ne.D.cwiseInverse().cwiseProduct(y);
    const double step = max_sigma_step(ne, dx);
    if (!std::isfinite(step)) {
      sum.message = "the normal equations are singular";
      break;
    }
    if (step < s.step_tolerance_sigma && lambda == 0.0) {
      const double rho_now = last_step > 1e-3 ? std::max(rho, step / last_step) : rho;
      if (at_J ||
          (rho_now > 0.0 && rho_now * std::sqrt(std::max(cost, 1.0)) < s.stale_jacobian_sigma)) {
        sum.converged = true;
        sum.message = "step below " + std::to_string(s.step_tolerance_sigma) + " sigma";
        break;
      }
      refresh();
      continue;
    }
    x_t = x;
    for (Eigen::Index a = 0; a < q; ++a) x_t[idx[static_cast<std::size_t>(a)]] += dx[a];
    pr.model.evaluate(x_t, r_t, nullptr);
    ++sum.residual_evaluations;
    rw_t = r_t;
    pr.weigh(rw_t);
    const double cost_t = rw_t.squaredNorm();
    // A step below 1e-3 sigma changes chi2 by < 1e-6: its sign is round-off, so it is taken.
    if (std::isfinite(cost_t) &&
        (cost_t <= cost * (1.0 + 1e-12) || (step < 1e-3 && cost_t <= cost + 1e-6))) {
      x.swap(x_t);
      ev.r.swap(r_t);
      ev.rw.swap(rw_t);
      cost = cost_t;
      ++sum.iterations;
      lambda = 0.0;
      const bool slow = last_step >= 0.0 && step > 0.1 * last_step;
      if (last_step > 1e-3) rho = std::max(rho, step / last_step);
      last_step = step;
      at_J = false;
      if (slow) refresh();
      continue;
    }
    // No decrease: first bring the Jacobian to this point, then damp (Levenberg-Marquardt).
    if (!at_J) {
      refresh();
      continue;
    }
    lambda = lambda > 0.0 ? lambda * 10.0 : 1e-4;
    if (lambda > 1e10) {
      sum.message = "no step reduces the cost";
      break;
    }
  }
  return ne;
}

// Covariance and outputs at the solution x, from the last normal equations `ne`.
void finish_outcome(const JointProblem& pr, const std::vector<Eigen::Index>& idx,
                    const NormalEquations& ne, double cost, Eigen::VectorXd& x, FullEvaluation& ev,
                    std::vector<bool>& observable, JointFitOutcome& out) {
  const JointFitSettings& s = pr.s;
  const Eigen::Index q = static_cast<Eigen::Index>(idx.size()), n = pr.n, p = pr.p;
  FitSummary& sum = out.summary;
  const double dof = std::max(1.0, static_cast<double>(n - q));
  sum.chi2 = cost;
  sum.chi2_per_dof = cost / dof;
  out.values = x;
  out.residuals = -ev.r;
  // (Jw^T Jw)^-1 of the free parameters from the last normal equations (Jacobian within 0.01
  // sigma of the solution), scaled by s^2 / sigma^2 without a whitener.
  out.residual_variance = s.whitener ? 1.0 : ev.r.squaredNorm() / dof;
  const double ratio = s.whitener ? 1.0 : out.residual_variance / (s.sigma * s.sigma);
  out.covariance = Eigen::MatrixXd::Zero(p, p);
  for (Eigen::Index a = 0; a < q; ++a)
    for (Eigen::Index b = 0; b < q; ++b)
      out.covariance(idx[static_cast<std::size_t>(a)], idx[static_cast<std::size_t>(b)]) =
          ne.Ainv(a, b) / (ne.D[a] * ne.D[b]) * ratio;
  if (s.whitener) {
    // The unwhitened Jacobian for the caller (Jw was whitened in place).
    out.jacobian.resize(n, p);
    Eigen::VectorXd tmp(n);
    pr.model.evaluate(x, tmp, &out.jacobian);
  } else {
    out.jacobian = std::move(ev.Jw);  // J itself (jw_scale above)
  }
  apply_yield_convention(pr.params, pr.analysed, pr.scales(), out, observable);
  x = out.values;
  for (int j = 0; j < p; ++j) {
    ParameterEstimate e;
    e.name = pr.params[static_cast<std::size_t>(j)].name;
    e.unit = pr.params[static_cast<std::size_t>(j)].unit;
    e.value = x[j];
    e.std = std::sqrt(std::max(0.0, out.covariance(j, j)));
    e.observable = observable[static_cast<std::size_t>(j)];
    out.estimates.push_back(std::move(e));
  }
}

}  // namespace

JointFitOutcome solve_joint(const ResidualModel& model, const std::vector<FitParameter>& params,
                            const JointFitSettings& s) {
  const JointProblem pr(model, params, s);
  JointFitOutcome out;
  FitSummary& sum = out.summary;
  sum.whitened = static_cast<bool>(s.whitener);
  sum.num_residuals = static_cast<std::size_t>(pr.n);
  Eigen::VectorXd x(pr.p);
  for (int j = 0; j < pr.p; ++j) x[j] = params[static_cast<std::size_t>(j)].start;
  const Eigen::VectorXd x0 = x;
  const std::vector<bool> free_subset = subsample_start(pr, x, sum);

  FullEvaluation ev(pr);
  ev.evaluate(pr, x, sum);
  std::vector<bool> observable = analyse_full(pr, free_subset, x0, x, ev, out);
  const std::vector<Eigen::Index> idx = free_indices(out.free);
  sum.num_free = static_cast<int>(idx.size());
  if (pr.n < static_cast<Eigen::Index>(idx.size()))
    throw InvalidArgument("solve_joint: " + std::to_string(pr.n) + " residuals cannot determine " +
                          std::to_string(idx.size()) + " unknowns");

  double cost = 0.0;
  const NormalEquations ne = gauss_newton(pr, idx, x, ev, sum, cost);
  finish_outcome(pr, idx, ne, cost, x, ev, observable, out);
  return out;
}

}  // namespace rotacal
