// Test design: the single set-up ballbar test with the smallest predicted uncertainty.
#include "rotacal/ballbar/design.hpp"

#include <ceres/jet.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/least_squares.hpp"

namespace rotacal {

namespace {

std::string fmt(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// The first plan sample whose machine axes leave the travel, in words; empty if none does.
std::string travel_violation(const BallbarPlan& plan, const Eigen::Vector3d& lo,
                             const Eigen::Vector3d& hi) {
  const char* axis = "XYZ";
  for (const PlanSegment& seg : plan.segments)
    for (const PlannedSample& s : seg.samples)
      for (int k = 0; k < 3; ++k)
        if (s.xyz[k] < lo[k] || s.xyz[k] > hi[k])
          return std::string(1, axis[k]) + " = " + fmt(s.xyz[k], 3) + " mm in " + seg.label +
                 " is outside the travel " + fmt(lo[k]) + ".." + fmt(hi[k]) + " mm";
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
  for (int i = 0; i < 8; ++i) {
    const double u =
        2.0 * c.sigma[i] * (location_error_is_angle(i) ? o.reference_radius_mm * 1e3 : 1e3);
    if (u > c.worst_expanded_um)
      c.worst_expanded_um = u, c.worst_error = c.names[static_cast<std::size_t>(i)];
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
      throw InvalidArgument("design: " + f.id() +
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
          reasons += "; L0 " + fmt(L) + ", pivot (" + fmt(x) + ", 0, " + fmt(z) + "): " + c.why_not;
        out.candidates.push_back(std::move(c));
      }
  if (!out.best.feasible)
    throw InvalidArgument("design: no candidate set-up is feasible" + reasons);
  if (out.baseline.feasible)
    out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal

// ------------------------------------------------------------------ separating two effects

namespace rotacal {

namespace {

using Jet1 = ceres::Jet<double, 1>;

// Orthonormal basis of span(M): left singular vectors whose singular value exceeds
// tol (absolute).
Eigen::MatrixXd basis(const Eigen::MatrixXd& M, double tol) {
  if (M.cols() == 0) return Eigen::MatrixXd(M.rows(), 0);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU);
  int r = 0;
  while (r < svd.singularValues().size() && svd.singularValues()[r] > tol) ++r;
  return svd.matrixU().leftCols(r);
}

// Table motion of every unknown at every pose, 6 rows per pose (omega x r_ref, then v, mm):
// columns 8 location errors, 3 table-point shift (R dq), then fx's parameters. Each column is
// one forward-mode pass with a one-wide Jet seeded on that unknown.
Eigen::MatrixXd table_motion_columns(MachineType m, const EffectModel& fx,
                                     const std::vector<RotaryAngles<double>>& poses,
                                     const std::vector<double>& times, double r_ref) {
  const int P = fx.num_params();
  const int cols = 11 + P;
  Eigen::MatrixXd G(6 * static_cast<Eigen::Index>(poses.size()), cols);
  for (int c = 0; c < cols; ++c) {
    LocationErrors<Jet1> e;
    Vec3<Jet1> dq = Vec3<Jet1>::Zero();
    std::vector<Jet1> q(static_cast<std::size_t>(std::max(P, 1)), Jet1(0.0));
    if (c < 8)
      e.v[c].v[0] = 1.0;
    else if (c < 11)
      dq[c - 8].v[0] = 1.0;
    else
      q[static_cast<std::size_t>(c - 11)].v[0] = 1.0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      Pose<Jet1> T = table_pose<Jet1>(m, e, fx, q.data(), poses[i], times[i]);
      T.t += T.R * dq;  // the table point moved in the table frame
      Eigen::Matrix3d R0, dR;
      Eigen::Vector3d t0, dt;
      for (int a = 0; a < 3; ++a) {
        t0[a] = T.t[a].a;
        dt[a] = T.t[a].v[0];
        for (int b = 0; b < 3; ++b) R0(a, b) = T.R(a, b).a, dR(a, b) = T.R(a, b).v[0];
      }
      const Eigen::Matrix3d W = dR * R0.transpose();  // skew(omega)
      const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
      const Eigen::Index row = 6 * static_cast<Eigen::Index>(i);
      G.block<3, 1>(row, c) = w * r_ref;
      G.block<3, 1>(row + 3, c) = dt - w.cross(t0);
    }
  }
  return G;
}

std::string deg_range(std::array<double, 2> r) {
  return fmt(r[0], 0) + ".." + fmt(r[1], 0) + " deg";
}

}  // namespace

namespace design_detail {

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

// Largest canonical correlation between the estimates of the determined parameters among
// [a0, a0 + na) and among [b0, b0 + nb): the largest correlation of any combination of one
// block with any of the other (held parameters are fixed, as in the fit); 1 when no
// parameter of a block is determined.
double canonical_correlation(const Inverted& inv, int a0, int na, int b0, int nb) {
  std::vector<Eigen::Index> ia, ib;
  for (int j = 0; j < na; ++j)
    if (inv.determined[static_cast<std::size_t>(a0 + j)]) ia.push_back(a0 + j);
  for (int j = 0; j < nb; ++j)
    if (inv.determined[static_cast<std::size_t>(b0 + j)]) ib.push_back(b0 + j);
  if (ia.empty() || ib.empty()) return 1.0;
  const Eigen::MatrixXd Caa = inv.cov(ia, ia), Cbb = inv.cov(ib, ib), Cab = inv.cov(ia, ib);
  const Eigen::LLT<Eigen::MatrixXd> la(Caa), lb(Cbb);
  if (la.info() != Eigen::Success || lb.info() != Eigen::Success) return 1.0;
  Eigen::MatrixXd M = la.matrixL().solve(Cab);
  M = lb.matrixL().solve(M.transpose()).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
  return std::min(1.0, svd.singularValues()[0]);
}

}  // namespace design_detail

TableMotionOverlap table_motion_overlap(MachineType m, const Effect& a, const Effect& b,
                                        std::array<double, 2> tilt, double duration_s,
                                        double r_ref) {
  for (const Effect* f : {&a, &b})
    if (!f->applies_to(m))
      throw InvalidArgument("effect " + f->id() + " does not exist on a " + to_string(m));
  if (!(tilt[0] < tilt[1]))
    throw InvalidArgument("table_motion_overlap: the tilt limits must be min < max deg");
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s))
    throw InvalidArgument("table_motion_overlap: the duration must be >= 0 s");
  if (!(r_ref > 0.0))
    throw InvalidArgument("table_motion_overlap: the reference radius must be > 0 mm");
  // 19 tilt angles x 24 C angles x 3 times: every harmonic up to 4 is resolved on both axes.
  std::vector<RotaryAngles<double>> poses;
  std::vector<double> times;
  const double deg = M_PI / 180.0;
  for (int it = 0; it < 3; ++it)
    for (int i = 0; i < 19; ++i)
      for (int k = 0; k < 24; ++k) {
        poses.push_back({(tilt[0] + (tilt[1] - tilt[0]) * i / 18.0) * deg, k * 15.0 * deg});
        times.push_back(duration_s * it / 2.0);
      }
  EffectModel fx;
  fx.effects = {a, b};
  const Eigen::MatrixXd G = table_motion_columns(m, fx, poses, times, r_ref);
  const int na = a.num_params(), nb = b.num_params();
  const Eigen::MatrixXd E1 = G.middleCols(11, na), E2 = G.middleCols(11 + na, nb);
  const double n1 = E1.norm(), n2 = E2.norm(), scale = std::max(G.leftCols(11).norm(), 1.0);
  TableMotionOverlap out;
  out.moves_table_first = n1 > 1e-12 * scale;
  out.moves_table_second = n2 > 1e-12 * scale;
  const std::string range =
      "tilt " + deg_range(tilt) + ", C over a full turn, time 0.." + fmt(duration_s, 0) + " s";
  if (!out.moves_table_first || !out.moves_table_second) {
    out.why =
        (out.moves_table_first ? b : a).id() +
        " does not move the table (it acts on the tool side or in the instrument), so the table "
        "motion cannot decide: an added test is searched";
    return out;
  }
  const Eigen::MatrixXd Q = basis(G.leftCols(11), 1e-10 * G.leftCols(11).norm());
  const Eigen::MatrixXd A1 = E1 - Q * (Q.transpose() * E1), A2 = E2 - Q * (Q.transpose() * E2);
  const Eigen::MatrixXd U1 = basis(A1, 1e-7 * n1), U2 = basis(A2, 1e-7 * n2);
  out.first_is_location = U1.cols() == 0;
  out.second_is_location = U2.cols() == 0;
  if (out.first_is_location || out.second_is_location) {
    out.same_motion = true;
    out.cosine = 1.0;
    const Effect& loc = out.first_is_location ? a : b;
    out.why =
        "at every pose (" + range + ") " + loc.id() +
        " moves the table only as the location errors and the set-up's table point do: every "
        "instrument reads the table's motion and fits those, so no test determines it, whatever "
        "the other effect; only changing its cause can (" +
        loc.cause() + ")";
    return out;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(U1.transpose() * U2);
  out.cosine = std::min(1.0, svd.singularValues()[0]);
  out.same_motion = out.cosine >= 1.0 - 1e-6;
  std::ostringstream w;
  w.precision(6);
  if (out.same_motion) {
    w << "at every pose (" << range << ") a combination of " << a.id()
      << "'s parameters moves the table exactly as one of " << b.id()
      << "'s does, together with the location errors and the set-up's table point (cosine of their "
         "table motions "
      << std::fixed << out.cosine
      << "): every instrument reads the table's motion, so no test can tell them apart; only "
         "changing "
         "the cause of one of them can ("
      << a.id() << ": " << a.cause() << "; " << b.id() << ": " << b.cause() << ")";
  } else {
    w << "their table motions differ (largest cosine " << std::fixed << out.cosine
      << " once the location errors and the table point are taken out, over " << range
      << "): a test that reads the difference separates them";
  }
  out.why = w.str();
  return out;
}

namespace {

std::string vec_text(const Eigen::Vector3d& v) {
  return "(" + fmt(v[0]) + ", " + fmt(v[1]) + ", " + fmt(v[2]) + ") mm";
}

}  // namespace

namespace {

// r_i = L_model,i - L_i (mm), sessions back to back; pivot of session s at 8 + 3 s.
struct SessionsLengthModel : ResidualModel {
  const std::vector<BallbarArrays>& d;
  const EffectModel& fx;
  int ns, P;                  // ns: pivots (columns 8 + 3 k), P: effect parameters
  std::vector<int> pivot_of;  // pivot index of each session
  std::vector<std::pair<int, Eigen::Index>> rows;  // (session, row) of every residual
  SessionsLengthModel(const std::vector<BallbarArrays>& d_, const EffectModel& fx_,
                      std::vector<int> pivot_of_, int P_)
      : d(d_),
        fx(fx_),
        ns(*std::max_element(pivot_of_.begin(), pivot_of_.end()) + 1),
        P(P_),
        pivot_of(std::move(pivot_of_)) {
    for (int s = 0; s < static_cast<int>(d.size()); ++s)
      for (Eigen::Index i = 0; i < d[static_cast<std::size_t>(s)].size(); ++i)
        rows.push_back({s, i});
  }
  Eigen::Index num_residuals() const override { return static_cast<Eigen::Index>(rows.size()); }
  int num_parameters() const override { return 8 + 3 * ns + P; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    evaluate_with_jets([this](Eigen::Index k, const auto* p, auto* out) { sample(k, p, out); },
                       num_residuals(), 1, x, r, J);
  }
  template <typename T>
  void sample(Eigen::Index k, const T* p, T* out) const {
    const int s = rows[static_cast<std::size_t>(k)].first;
    const Eigen::Index i = rows[static_cast<std::size_t>(k)].second;
    const BallbarArrays& a = d[static_cast<std::size_t>(s)];
    const int piv = pivot_of[static_cast<std::size_t>(s)];
    const Vec3<T> pivot(p[8 + 3 * piv], p[9 + 3 * piv], p[10 + 3 * piv]);
    const Eigen::Vector3d xyz = a.xyz.col(i);
    out[0] = predicted_length<T>(a.machine, LocationErrors<T>::from_ptr(p), pivot, fx,
                                 P > 0 ? p + 8 + 3 * ns : nullptr, xyz,
                                 a.angles[static_cast<std::size_t>(i)], a.time[i],
                                 a.motion[static_cast<std::size_t>(i)]) -
             T(a.length[i]);
  }
};

// Jacobian (mm per unit) of the ballbar lengths of `s` at zero errors and the nominal pivot:
// the joint fit's model without solving it (8 location errors, pivot, effects).
Eigen::MatrixXd nominal_jacobian(const BallbarSession& s, const EffectModel& fx) {
  const std::vector<BallbarArrays> data = {ballbar_arrays(s)};
  const SessionsLengthModel model(data, fx, {0}, fx.num_params());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(model.num_parameters());
  x.segment<3>(8) = data[0].pivot;
  Eigen::VectorXd r(model.num_residuals());
  Eigen::MatrixXd J(model.num_residuals(), model.num_parameters());
  model.evaluate(x, r, &J);
  return J;
}

}  // namespace

SeparationDesign design_ballbar_separation(const BallbarSession& session,
                                           const std::vector<Effect>& pair,
                                           const SeparationOptions& o) {
  using design_detail::canonical_correlation;
  using design_detail::invert_information;
  using design_detail::Inverted;
  if (pair.size() != 2 || pair[0] == pair[1])
    throw InvalidArgument("design: --separate needs two different effects (EFFECT,EFFECT)");
  if (session.samples.empty()) throw InvalidArgument("design: --after: the session has no samples");
  if (o.bar_lengths_mm.empty() || o.pivot_radius_mm.empty() || o.pivot_angle_deg.empty() ||
      o.pivot_z_mm.empty())
    throw InvalidArgument(
        "design: --lengths, --pivot-r, --pivot-angle and --pivot-z need at least one value each");
  if (!(o.max_added_time_s > 0.0) || !std::isfinite(o.max_added_time_s))
    throw InvalidArgument("design: --max-time must be > 0 s");
  if (!(o.max_correlation > 0.0 && o.max_correlation < 1.0))
    throw InvalidArgument("design: --max-correlation must be in (0, 1)");
  if (!(o.noise_um >= 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("design: --noise must be >= 0 um");
  if (!(o.tilt_limits_deg[0] < o.tilt_limits_deg[1]))
    throw InvalidArgument("design: --tilt-limits must be min < max deg");
  const MachineType m = session.machine;
  SeparationDesign D;
  D.effects = {pair[0].id(), pair[1].id()};
  EffectModel fx;
  fx.effects = pair;
  fx.linear_reference = mean_commanded_xyz(session.samples);
  const double t_end = session.samples.back().time;
  D.motion = table_motion_overlap(m, pair[0], pair[1], o.tilt_limits_deg,
                                  t_end + o.max_added_time_s, o.reference_radius_mm);

  // The session's information: its joint-fit Jacobian (pair included) over its noise, whose
  // model comes from the residuals of the fit.
  JointFitOptions fo;
  fo.effects = fx;
  fo.noise = NoiseHandling::white;
  const BallbarIdentification id = identify_joint(session, fo);
  const int na = pair[0].num_params(), nb = pair[1].num_params(), ne = na + nb;
  const int p0 = 11 + ne;
  double sigma_um = o.noise_um > 0.0 ? o.noise_um : id.noise.sigma_um;
  if (!(sigma_um > 0.0)) sigma_um = id.sigma_um;
  if (!(sigma_um > 0.0))
    throw InvalidArgument(
        "design: --after: the session's residuals are zero (commanded data?); give --noise");
  D.noise_um = sigma_um;
  if (id.noise.n > 0 && id.noise.effective_samples > 0.0)
    D.effective_per_reading =
        std::min(1.0, id.noise.effective_samples / static_cast<double>(id.noise.n));
  const double w = D.effective_per_reading / (sigma_um * sigma_um * 1e-6);
  // The Jacobian at the start point, where the fit judges what it can see (at its solution,
  // location errors of 0.1 mm lend second-order sensitivity that the fit does not use).
  const Eigen::MatrixXd Js = nominal_jacobian(session, fx);
  const Eigen::MatrixXd Is = Js.transpose() * Js * w;
  for (const ParameterEstimate& e : id.parameters) D.names.push_back(e.name);
  // Plausible magnitudes by unit (1 mm, 1 mrad, ...), as the fit's observability test uses.
  Eigen::VectorXd plausible = Eigen::VectorXd::Constant(p0 + 3, plausible_magnitude("mm"));
  for (int j = 0; j < p0; ++j)
    plausible[j] = plausible_magnitude(id.parameters[static_cast<std::size_t>(j)].unit);
  const Inverted before = invert_information(Is, plausible.head(p0), 1.0 / D.effective_per_reading);
  D.sigma_before = before.sigma;
  D.correlation_before = canonical_correlation(before, 11, na, 11 + na, nb);
  D.sigma_after = D.sigma_before;
  D.chosen.correlation = D.correlation_before;
  if (D.motion.same_motion) {
    D.verdict =
        "no test can separate " + D.effects[0] + " and " + D.effects[1] + ": " + D.motion.why;
    return D;
  }
  if (D.correlation_before < o.max_correlation) {
    D.already_separated = true;
    std::ostringstream v;
    v.precision(2);
    v << std::fixed << "the session alone separates " << D.effects[0] << " and " << D.effects[1]
      << " (correlation " << D.correlation_before << " < " << o.max_correlation
      << "): no added test is needed";
    D.verdict = v.str();
    return D;
  }

  // Candidates: from the session's pivot, one rotary test at each bar length and range (the
  // pivot is shared with the session); from a moved pivot, the sphere tests that locate it
  // and one rotary test.
  std::vector<std::pair<BallbarSetup, bool>> cands;
  const std::vector<BallbarTest> rotary = {BallbarTest::radial_c, BallbarTest::axial_c,
                                           BallbarTest::radial_tilt, BallbarTest::axial_tilt};
  const std::array<double, 2> lim = o.tilt_limits_deg;
  std::vector<std::array<double, 2>> tilt_ranges = {lim};
  if (lim[0] < 0.0 && lim[1] > 0.0)
    tilt_ranges.push_back({lim[0], 0.0}), tilt_ranges.push_back({0.0, lim[1]});
  BallbarSetup base = o.added;
  base.machine = m;
  for (double L : o.bar_lengths_mm)
    for (BallbarTest t : rotary) {
      const bool tilt_test = t == BallbarTest::radial_tilt || t == BallbarTest::axial_tilt;
      for (const auto& tr : tilt_test ? tilt_ranges : std::vector<std::array<double, 2>>{lim})
        for (RadialSide side :
             t == BallbarTest::radial_c
                 ? std::vector<RadialSide>{RadialSide::outside, RadialSide::inside}
                 : std::vector<RadialSide>{RadialSide::outside}) {
          BallbarSetup s = base;
          s.ballbar_length = L;
          s.pivot = session.pivot;
          s.tests = {t};
          s.tilt_range_deg = tr;
          s.radial_c_side = side;
          cands.push_back({s, false});
        }
    }
  // Effects of the motion itself show in a tangential test run both ways (backlash and lag
  // against the zero offset) and at a second feed (servo lag, proportional to the speed,
  // against backlash): those runs from the session's pivot.
  bool motion_pair = false;
  for (const std::string& id : D.effects) motion_pair = motion_pair || Effect::parse(id).depends_on_motion();
  if (motion_pair)
    for (double L : o.bar_lengths_mm)
      for (BallbarTest t : {BallbarTest::tangential_c, BallbarTest::tangential_tilt})
        for (const std::vector<double>& feeds : {std::vector<double>{1.0}, std::vector<double>{1.0, 2.0}}) {
          BallbarSetup s = base;
          s.ballbar_length = L;
          s.pivot = session.pivot;
          s.tests = {t};
          s.tilt_range_deg = lim;
          s.directions = {SweepDirection::ccw, SweepDirection::cw};
          s.feed_factors = feeds;
          cands.push_back({s, false});
        }
  const double deg = M_PI / 180.0;
  for (double r : o.pivot_radius_mm)
    for (double ang : o.pivot_angle_deg)
      for (double z : o.pivot_z_mm) {
        Eigen::Vector3d pv(r * std::cos(ang * deg), r * std::sin(ang * deg), z);
        pv = (pv * 1e9).array().round() / 1e9;  // cos 90 deg is 6e-17, not 0
        if ((pv - session.pivot).norm() < 1e-6) continue;
        if (r == 0.0 && ang != o.pivot_angle_deg.front()) continue;  // one pivot on the axis
        for (double L : o.bar_lengths_mm)
          for (BallbarTest t : rotary) {
            BallbarSetup s = base;
            s.ballbar_length = L;
            s.pivot = pv;
            s.tilt_range_deg = lim;
            s.tests = {BallbarTest::sphere_xy, BallbarTest::sphere_yz, BallbarTest::sphere_zx, t};
            cands.push_back({s, true});
          }
      }

  bool have_best = false, have_fallback = false;
  Eigen::MatrixXd best_info;
  for (const auto& [setup, moved] : cands) {
    BallbarPlan plan;
    try {
      plan = plan_ballbar_test(setup);
    } catch (const InvalidArgument&) {
      continue;  // e.g. an inside radial C circle the bar cannot reach
    }
    if (!travel_violation(plan, o.travel_min, o.travel_max).empty()) continue;
    const double duration = plan.duration();
    if (duration > o.max_added_time_s) continue;
    ++D.candidates_tried;
    BallbarSession cmd = commanded_session(plan);
    for (BallbarSample& smp : cmd.samples) smp.time += t_end;  // after the session
    const Eigen::MatrixXd Ja = nominal_jacobian(cmd, fx);
    // Map the added test's columns (8 location, 3 pivot, effects) to the joint ones.
    const int p = p0 + (moved ? 3 : 0);
    Eigen::MatrixXd Jm = Eigen::MatrixXd::Zero(Ja.rows(), p);
    Jm.leftCols(8) = Ja.leftCols(8);
    Jm.middleCols(moved ? p0 : 8, 3) = Ja.middleCols(8, 3);
    Jm.middleCols(11, ne) = Ja.middleCols(11, ne);
    const Eigen::MatrixXd Ia = Jm.transpose() * Jm * w;
    Eigen::MatrixXd I0 = Eigen::MatrixXd::Zero(p, p);
    I0.topLeftCorner(p0, p0) = Is;
    // Slowing a test down gathers more readings of the same signature, except where the
    // signature depends on the speed: runs at set feeds are taken as planned.
    const bool set_feeds = setup.directions.size() > 1 || setup.feed_factors.size() > 1;
    for (double slow = 1.0; duration * slow <= o.max_added_time_s * (1 + 1e-12) && (slow == 1.0 || !set_feeds);
         slow *= 2.0) {
      const Eigen::MatrixXd I = I0 + slow * Ia;
      const Inverted inv = invert_information(I, plausible.head(p), 1.0 / D.effective_per_reading);
      SeparatingCandidate c;
      c.setup = setup;
      c.new_pivot = moved;
      c.duration_s = duration;
      c.slow_down = slow;
      c.correlation = canonical_correlation(inv, 11, na, 11 + na, nb);
      c.determined = true;
      for (int j = 11; j < 11 + ne; ++j)
        c.determined = c.determined && inv.determined[static_cast<std::size_t>(j)];
      const bool ok = c.correlation < o.max_correlation;
      const double run = duration * slow;
      if (ok) {
        if (!have_best || run < D.chosen.duration_s * D.chosen.slow_down - 1e-9 ||
            (std::abs(run - D.chosen.duration_s * D.chosen.slow_down) <= 1e-9 &&
             c.correlation < D.chosen.correlation)) {
          D.chosen = c;
          best_info = I;
          have_best = true;
        }
        break;
      }
      if (!have_best && (!have_fallback || c.correlation < D.chosen.correlation)) {
        D.chosen = c;
        best_info = I;
        have_fallback = true;
      }
    }
  }
  D.found = have_best;
  if (have_best || have_fallback) {
    SeparatingCandidate& c = D.chosen;
    std::ostringstream d;
    const std::string label = test_label(c.setup.tests.back(), m);
    const bool tilt_test = c.setup.tests.back() == BallbarTest::radial_tilt ||
                           c.setup.tests.back() == BallbarTest::axial_tilt ||
                           c.setup.tests.back() == BallbarTest::tangential_tilt;
    d << label;
    if (tilt_test) d << " over " << deg_range(c.setup.tilt_range_deg);
    if (c.setup.tests.back() == BallbarTest::radial_c)
      d << " (tool circle " << to_string(c.setup.radial_c_side) << ")";
    if (c.setup.directions.size() > 1) d << " ccw and cw";
    if (c.setup.feed_factors.size() > 1) {
      d << " at";
      for (std::size_t k = 0; k < c.setup.feed_factors.size(); ++k)
        d << (k ? ", " : " ") << fmt(c.setup.feed_mm_per_min * c.setup.feed_factors[k], 0);
      d << " mm/min";
    }
    d << " with the " << fmt(c.setup.ballbar_length, 0) << " mm bar";
    if (c.new_pivot)
      d << ", pivot moved to " << vec_text(c.setup.pivot)
        << " (after sphere_xy, sphere_yz, sphere_zx to locate it)";
    else
      d << ", from the session's pivot " << vec_text(c.setup.pivot);
    if (c.slow_down > 1.0) d << ", at 1/" << fmt(c.slow_down, 0) << " of the feeds";
    c.description = d.str();
    const Inverted after = invert_information(best_info, plausible.head(best_info.rows()),
                                              1.0 / D.effective_per_reading);
    D.sigma_after = after.sigma;
    if (c.new_pivot)
      for (const char* n : {"pivot_x#2", "pivot_y#2", "pivot_z#2"}) D.names.push_back(n);
  }
  std::ostringstream v;
  v.precision(2);
  v << std::fixed;
  if (D.found)
    v << "add " << D.chosen.description << ": " << fmt(D.chosen.duration_s * D.chosen.slow_down, 0)
      << " s; fitted with the session, the correlation of " << D.effects[0] << " and "
      << D.effects[1] << " goes from " << D.correlation_before << " to " << D.chosen.correlation;
  else
    v << "none of " << D.candidates_tried << " added tests within " << fmt(o.max_added_time_s, 0)
      << " s brings the correlation of " << D.effects[0] << " and " << D.effects[1] << " below "
      << o.max_correlation
      << (D.candidates_tried
              ? "; the closest is " + D.chosen.description + " (correlation " +
                    fmt(D.chosen.correlation, 2) + "): a longer test or another instrument may"
              : std::string("; every candidate breaks a limit"));
  if (D.candidates_tried) {
    std::string held;
    for (std::size_t j = 11; j < 11 + static_cast<std::size_t>(ne); ++j)
      if (!std::isfinite(D.sigma_after[static_cast<Eigen::Index>(j)]))
        held += (held.empty() ? "" : ", ") + D.names[j];
    if (!held.empty())
      v << "; " << held
        << " remain undetermined (no reading of these tests sees them: the joint fit holds them at "
           "0, and "
           "the correlation is that of the rest)";
  }
  D.verdict = v.str();
  return D;
}

JointFitOutcome identify_joint_sessions(const std::vector<BallbarSession>& sessions,
                                        const EffectModel& effects) {
  if (sessions.empty()) throw InvalidArgument("identify_joint_sessions: no session");
  const MachineType m = sessions.front().machine;
  for (const BallbarSession& s : sessions)
    if (s.machine != m)
      throw InvalidArgument("identify_joint_sessions: the sessions are of different machines");
  for (const Effect& f : effects.effects)
    if (!f.applies_to(m))
      throw InvalidArgument("effect " + f.id() + " does not exist on a " + to_string(m));
  std::vector<BallbarArrays> data;
  for (const BallbarSession& s : sessions) data.push_back(ballbar_arrays(s));
  // Sessions with the same nominal pivot share it (the ball stayed in its cup).
  std::vector<int> pivot_of;
  std::vector<Eigen::Vector3d> pivots;
  for (const BallbarSession& s : sessions) {
    int k = 0;
    while (k < static_cast<int>(pivots.size()) &&
           (pivots[static_cast<std::size_t>(k)] - s.pivot).norm() > 1e-9)
      ++k;
    if (k == static_cast<int>(pivots.size())) pivots.push_back(s.pivot);
    pivot_of.push_back(k);
  }
  const int ns = static_cast<int>(pivots.size()), P = effects.num_params();
  std::vector<FitParameter> params;
  for (int k = 0; k < 8; ++k)
    params.push_back({location_error_names(m)[static_cast<std::size_t>(k)],
                      location_error_is_angle(k) ? "rad" : "mm", 0.0});
  const char* axis = "xyz";
  for (int s = 0; s < ns; ++s)
    for (int k = 0; k < 3; ++k)
      params.push_back({std::string("pivot_") + axis[k] + "#" + std::to_string(s + 1), "mm",
                        pivots[static_cast<std::size_t>(s)][k]});
  for (const std::string& l : effects.param_labels()) params.push_back({l, "", 0.0});
  for (std::size_t j = 8 + 3 * static_cast<std::size_t>(ns); j < params.size(); ++j) {
    // Units of the effect parameters, in label order.
    std::size_t k = j - 8 - 3 * static_cast<std::size_t>(ns);
    for (const Effect& f : effects.effects) {
      const auto u = f.param_units();
      if (k < u.size()) {
        params[j].unit = u[k];
        break;
      }
      k -= u.size();
    }
  }
  const SessionsLengthModel model(data, effects, pivot_of, P);
  JointFitSettings settings;
  settings.sigma = sessions.front().noise_um.value_or(1.0) * 1e-3;
  return solve_joint(model, params, settings);
}

}  // namespace rotacal
