// Test design: the single set-up ballbar test with the smallest predicted uncertainty.
#include "rotacal/ballbar/design.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <sstream>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

std::string fmt(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// The first plan sample whose machine axes leave the travel, or -1.
std::string travel_violation(const BallbarPlan& plan, const BallbarDesignOptions& o) {
  const char* axis = "XYZ";
  for (const PlanSegment& seg : plan.segments)
    for (const PlannedSample& s : seg.samples)
      for (int k = 0; k < 3; ++k)
        if (s.xyz[k] < o.travel_min[k] || s.xyz[k] > o.travel_max[k])
          return std::string(1, axis[k]) + " = " + fmt(s.xyz[k], 3) + " mm in " + seg.label + " is outside the travel " +
                 fmt(o.travel_min[k]) + ".." + fmt(o.travel_max[k]) + " mm";
  return {};
}

double test_time(const BallbarPlan& plan) {
  double t = 0.0;
  for (const PlanSegment& seg : plan.segments)
    if (seg.kind == SegmentKind::test && seg.samples.size() > 1)
      t += seg.samples.back().time - seg.samples.front().time;
  return t;
}

}  // namespace

DesignCandidate evaluate_design(const BallbarSetup& setup, const BallbarDesignOptions& o, double budget) {
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
  c.why_not = travel_violation(plan, o);
  if (!c.why_not.empty()) return c;
  if (budget <= 0.0) budget = c.duration_s;

  // The Jacobian of the joint model at the nominal machine, as the fit evaluates it.
  BallbarSession s = commanded_session(plan);
  s.noise_um = o.noise_um;
  JointFitOptions fit;
  fit.effects = o.effects_of_concern;
  const BallbarIdentification id = identify_joint(s, fit);
  const Eigen::MatrixXd& J = id.jacobian;
  const int p = static_cast<int>(id.parameters.size());
  for (int j = 0; j < p; ++j) c.names.push_back(id.parameters[static_cast<std::size_t>(j)].name);
  // A location error or the pivot that the set-up cannot see rules it out; an effect parameter
  // it cannot see is reported (sigma infinite, correlation 1): that pair needs another test.
  std::vector<int> free;
  for (int j = 0; j < p; ++j) {
    if (!id.fixed[static_cast<std::size_t>(j)]) {
      free.push_back(j);
    } else if (j < 11) {
      c.why_not = id.parameters[static_cast<std::size_t>(j)].name + " is not determined by this set-up";
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
  const Eigen::MatrixXd normalised = d.cwiseInverse().asDiagonal() * info * d.cwiseInverse().asDiagonal();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normalised);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12)) {
    c.why_not = "the information matrix is singular";
    return c;
  }
  const Eigen::MatrixXd corr_inv = ldlt.solve(Eigen::MatrixXd::Identity(q, q));
  const Eigen::MatrixXd cov_free = d.cwiseInverse().asDiagonal() * corr_inv * d.cwiseInverse().asDiagonal();
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(p, p, inf);
  for (int a = 0; a < q; ++a)
    for (int b = 0; b < q; ++b) cov(free[static_cast<std::size_t>(a)], free[static_cast<std::size_t>(b)]) = cov_free(a, b);
  c.sigma = cov.diagonal().cwiseSqrt();
  for (int i = 0; i < 8; ++i) {
    const double u = 2.0 * c.sigma[i] * (location_error_is_angle(i) ? o.reference_radius_mm * 1e3 : 1e3);
    if (u > c.worst_expanded_um) c.worst_expanded_um = u, c.worst_error = c.names[static_cast<std::size_t>(i)];
  }
  const int first_effect = p - o.effects_of_concern.num_params();
  for (int j = first_effect; j < p; ++j) {
    double loc = 0.0, other = 0.0;
    for (int i = 0; i < p; ++i) {
      if (i == j) continue;
      // Not determined: it cannot be told from the others at all.
      const double r = std::isfinite(c.sigma[j]) && std::isfinite(c.sigma[i])
                           ? std::abs(cov(i, j)) / (c.sigma[i] * c.sigma[j])
                           : 1.0;
      if (i < 8) loc = std::max(loc, r);
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
    throw InvalidArgument("design: --lengths, --pivot-x and --pivot-z need at least one value each");
  if (!(o.sample_rate_hz > 0.0)) throw InvalidArgument("design: --rate must be > 0 Hz");
  if (!(o.noise_um > 0.0)) throw InvalidArgument("design: --noise must be > 0 um");
  if (!(o.reference_radius_mm > 0.0)) throw InvalidArgument("design: the reference radius must be > 0 mm");
  if (!(o.noise_rho >= 0.0 && o.noise_rho <= 0.999)) throw InvalidArgument("design: --rho must be in [0, 0.999]");
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
        if (c.feasible && (!out.best.feasible || c.worst_expanded_um < out.best.worst_expanded_um)) out.best = c;
        if (!c.feasible && reasons.size() < 400) reasons += "; L0 " + fmt(L) + ", pivot (" + fmt(x) + ", 0, " + fmt(z) + "): " + c.why_not;
        out.candidates.push_back(std::move(c));
      }
  if (!out.best.feasible) throw InvalidArgument("design: no candidate set-up is feasible" + reasons);
  if (out.baseline.feasible) out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal
