// SPDX-License-Identifier: BSD-3-Clause
// Test design: the single set-up ballbar test with the smallest predicted uncertainty.
#include "rotacal/ballbar/design.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "rotacal/ballbar/problem.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/design/format.hpp"

namespace rotacal {

namespace {

double test_time(const BallbarPlan& plan) {
  double t = 0.0;
  for (const PlanSegment& seg : plan.segments)
    if (seg.kind == SegmentKind::test && seg.samples.size() > 1)
      t += seg.samples.back().time - seg.samples.front().time;
  return t;
}

}  // namespace

std::string travel_violation(const BallbarPlan& plan, const Eigen::Vector3d& lo,
                             const Eigen::Vector3d& hi) {
  const char* axis = "XYZ";
  for (const PlanSegment& seg : plan.segments)
    for (const PlannedSample& s : seg.samples)
      for (int k = 0; k < 3; ++k)
        if (s.xyz[k] < lo[k] || s.xyz[k] > hi[k])
          return std::string(1, axis[k]) + " = " + fixed_text(s.xyz[k], 3) + " mm in " + seg.label +
                 " is outside the travel " + fixed_text(lo[k]) + ".." + fixed_text(hi[k]) + " mm";
  return {};
}

DesignCandidate evaluate_design(const BallbarSetup& setup, const BallbarDesignOptions& o,
                                double budget) {
  DesignCandidate c;
  c.setup = setup;
  BallbarPlan plan;
  try {
    plan = plan_ballbar_test(setup);
  } catch (const InvalidArgument& e) {
    c.why_not = e.what();
    return c;
  }
  c.duration_s = plan.duration();
  c.why_not = travel_violation(plan, o.travel_min, o.travel_max);
  if (!c.why_not.empty()) return c;
  if (budget <= 0.0) budget = c.duration_s;

  // The Jacobian of the joint model at the nominal machine, as the fit evaluates it.
  BallbarSession s = commanded_session(plan);
  s.noise_um = o.noise_um;
  JointFitOptions fit;
  fit.effects = o.effects_of_concern;
  const BallbarIdentification id = identify_joint(s, fit);
  const BallbarLayout L = ballbar_layout(s.machine, id.model.effects);
  const Eigen::MatrixXd& J = id.jacobian;
  const int p = static_cast<int>(id.parameters.size());
  for (int j = 0; j < p; ++j) c.names.push_back(id.parameters[static_cast<std::size_t>(j)].name);
  // A location error or the pivot that the set-up cannot see rules it out; an effect parameter
  // it cannot see is reported (sigma infinite, correlation 1): that pair needs another test.
  std::vector<int> free;
  for (int j = 0; j < p; ++j) {
    if (!id.fixed[static_cast<std::size_t>(j)]) {
      free.push_back(j);
    } else if (j < L.effects.offset) {
      c.why_not =
          id.parameters[static_cast<std::size_t>(j)].name + " is not determined by this set-up";
      return c;
    }
  }
  const int q = static_cast<int>(free.size());
  Eigen::MatrixXd Jf(J.rows(), q);
  for (int a = 0; a < q; ++a) Jf.col(a) = J.col(free[static_cast<std::size_t>(a)]);

  // Samples recorded in the tests when the path is run to fill the budget, effective under
  // AR(1) noise; information per plan sample scaled to them.
  const double recorded = o.sample_rate_hz * test_time(plan) * (budget / c.duration_s);
  const double effective = recorded * (1.0 - o.noise_rho) / (1.0 + o.noise_rho);
  const double scale = effective / static_cast<double>(J.rows());
  const double s2 = o.noise_um * o.noise_um * 1e-6;
  Eigen::MatrixXd info = Jf.transpose() * Jf * (scale / s2);
  const Eigen::VectorXd d = info.diagonal().cwiseSqrt();
  const Eigen::MatrixXd normalised =
      d.cwiseInverse().asDiagonal() * info * d.cwiseInverse().asDiagonal();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normalised);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12)) {
    c.why_not = "the information matrix is singular";
    return c;
  }
  const Eigen::MatrixXd corr_inv = ldlt.solve(Eigen::MatrixXd::Identity(q, q));
  const Eigen::MatrixXd cov_free =
      d.cwiseInverse().asDiagonal() * corr_inv * d.cwiseInverse().asDiagonal();
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(p, p, inf);
  for (int a = 0; a < q; ++a)
    for (int b = 0; b < q; ++b)
      cov(free[static_cast<std::size_t>(a)], free[static_cast<std::size_t>(b)]) = cov_free(a, b);
  c.sigma = cov.diagonal().cwiseSqrt();
  for (Eigen::Index i = L.errors.offset; i < L.errors.end(); ++i) {
    const double u = 2.0 * c.sigma[i] *
                     (location_error_is_angle(static_cast<int>(i - L.errors.offset))
                          ? o.reference_radius_mm * 1e3
                          : 1e3);
    if (u > c.worst_expanded_um)
      c.worst_expanded_um = u, c.worst_error = c.names[static_cast<std::size_t>(i)];
  }
  // The effects of concern: the last of the effects block (a head's tool length comes first).
  const int first_effect = static_cast<int>(L.effects.end()) - o.effects_of_concern.num_params();
  for (int j = first_effect; j < p; ++j) {
    double loc = 0.0, other = 0.0;
    for (int i = 0; i < p; ++i) {
      if (i == j) continue;
      // Not determined: it cannot be told from the others at all.
      const double r = std::isfinite(c.sigma[j]) && std::isfinite(c.sigma[i])
                           ? std::abs(cov(i, j)) / (c.sigma[i] * c.sigma[j])
                           : 1.0;
      if (L.errors.contains(i)) loc = std::max(loc, r);
      if (i >= first_effect) other = std::max(other, r);
    }
    c.effect_vs_location.push_back(loc);
    c.effect_vs_effects.push_back(other);
  }
  c.feasible = true;
  return c;
}

BallbarDesign design_ballbar_test(const BallbarDesignOptions& o) {
  if (o.bar_lengths_mm.empty() || o.pivot_x_mm.empty() || o.pivot_z_mm.empty())
    throw InvalidArgument(
        "design: --lengths, --pivot-x and --pivot-z need at least one value each");
  if (!(o.sample_rate_hz > 0.0)) throw InvalidArgument("design: --rate must be > 0 Hz");
  if (!(o.noise_um > 0.0)) throw InvalidArgument("design: --noise must be > 0 um");
  if (!(o.reference_radius_mm > 0.0))
    throw InvalidArgument("design: the reference radius must be > 0 mm");
  // The design runs each path slower to fill the time budget, which changes what a motion
  // effect does: those are refused here rather than predicted wrongly.
  for (const Effect& f : o.effects_of_concern.effects)
    if (f.depends_on_motion())
      throw InvalidArgument(
          "design: " + f.id() +
          " depends on the speed, which the design changes to fill the time; it is "
          "not designed for yet (use --separate after a session with both directions)");
  if (!(o.noise_rho >= 0.0 && o.noise_rho <= 0.999))
    throw InvalidArgument("design: --rho must be in [0, 0.999]");
  if (!(o.time_budget_s >= 0.0) || !std::isfinite(o.time_budget_s))
    throw InvalidArgument("design: --time must be >= 0 s");
  BallbarDesign out;
  out.baseline = evaluate_design(o.base, o, o.time_budget_s);
  out.time_budget_s = o.time_budget_s > 0.0 ? o.time_budget_s : out.baseline.duration_s;
  if (!(out.time_budget_s > 0.0))
    throw InvalidArgument("design: the default set-up cannot be planned (" + out.baseline.why_not +
                          "); give --time");
  std::string reasons;
  for (double L : o.bar_lengths_mm)
    for (double x : o.pivot_x_mm)
      for (double z : o.pivot_z_mm) {
        BallbarSetup s = o.base;
        s.ballbar_length = L;
        s.pivot = Eigen::Vector3d(x, 0.0, z);
        DesignCandidate c = evaluate_design(s, o, out.time_budget_s);
        if (c.feasible && (!out.best.feasible || c.worst_expanded_um < out.best.worst_expanded_um))
          out.best = c;
        if (!c.feasible && reasons.size() < 400)
          reasons += "; L0 " + fixed_text(L) + ", pivot (" + fixed_text(x) + ", 0, " +
                     fixed_text(z) + "): " + c.why_not;
        out.candidates.push_back(std::move(c));
      }
  if (!out.best.feasible)
    throw InvalidArgument("design: no candidate set-up is feasible" + reasons);
  if (out.baseline.feasible)
    out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal
