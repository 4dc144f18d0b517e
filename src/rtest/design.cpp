// SPDX-License-Identifier: BSD-3-Clause
// Test design: the R-test nests and pose grid with the smallest predicted uncertainty.
#include "rotacal/rtest/design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/design/format.hpp"
#include "rotacal/design/separation.hpp"
#include "rotacal/rtest/model.hpp"
#include "rotacal/rtest/problem.hpp"

namespace rotacal {

namespace {

// The whitener of AR(1) noise with coefficient rho and marginal sigma per stream (one per nest
// and component dx, dy, dz, in time order, as noise_gen::ar1 and the noise model split them):
// the core's (core/noise_model.hpp) with its exact start-up row (Prais-Winsten),
//   w_0 = x_0 / sigma,   w_t = (x_t - rho x_{t-1}) / (sigma sqrt(1 - rho^2)).
// With it the joint fit's covariance is (J^T Sigma^-1 J)^-1, the GLS covariance under that
// noise, with no rescaling by the (zero) residual variance of noise-free readings. rho = 0
// gives W = I / sigma, i.e. (J^T J)^-1 sigma^2.
std::shared_ptr<const ResidualWhitener> ar1_whitener(const RtestSession& s, double sigma_um,
                                                     double rho) {
  std::vector<std::string> groups;
  std::vector<double> times;
  for (const RtestSample& x : s.samples)
    for (int k = 0; k < 3; ++k) groups.push_back(x.setup), times.push_back(x.time);
  const NoiseStreamLayout layout(groups, times);
  NoiseModel model;
  model.n = layout.n;
  for (std::size_t k = 0; k < layout.rows.size(); ++k) {
    NoiseStream stream;
    stream.group = layout.group[k];
    stream.channel = layout.channel[k];
    stream.rows = layout.rows[k];
    if (rho > 0.0) stream.ar = stream.reflection = {rho};
    stream.marginal_sigma_um = sigma_um;
    model.streams.push_back(std::move(stream));
  }
  return std::make_shared<ArWhitener>(model);
}

// BC-trt with the design's travel and B limits: the user's machine, which may be larger than
// the built-in description, whose travel would refuse the readings of a pattern the design
// allows (issue 32: --travel could not widen it).
MachineType design_machine(const RtestDesignOptions& o) {
  MachineDescription d = MachineType(MachineType::BC_trt).description();
  d.name = "BC-trt within the design's travel";
  Eigen::Matrix<double, 3, 2> travel;
  travel.col(0) = o.travel_min;
  travel.col(1) = o.travel_max;
  d.travel_mm = travel;
  for (RotaryAxis& a : d.table_axes)
    if (a.name == 'B') a.limits_deg = o.b_limits_deg;
  return MachineType::from_description(d);
}

// min, min + step, ..., up to max (the end added when off the grid).
std::vector<double> steps(double lo, double hi, double step) {
  std::vector<double> v;
  for (int k = 0; lo + k * step <= hi + 1e-9; ++k) v.push_back(lo + k * step);
  if (hi - v.back() > 1e-9) v.push_back(hi);
  return v;
}

}  // namespace

RtestDesignCandidate evaluate_rtest_design(const RtestPattern& pattern, const RtestDesignOptions& o,
                                           double budget) {
  RtestDesignCandidate c;
  c.pattern = pattern;
  const MachineType m = MachineType::BC_trt;
  const std::size_t poses = pattern.b_deg.size() * pattern.c_deg.size();
  c.duration_s = static_cast<double>(poses * pattern.nests.size()) * pattern.dwell_s;
  if (budget <= 0.0) budget = c.duration_s;
  if (c.duration_s > budget * (1 + 1e-12)) {
    c.why_not = fixed_text(c.duration_s, 0) + " s is over the time budget of " +
                fixed_text(budget, 0) + " s";
    return c;
  }
  const double deg = M_PI / 180.0;
  const char* axis = "XYZ";
  for (double b : pattern.b_deg)
    if (b < o.b_limits_deg[0] - 1e-9 || b > o.b_limits_deg[1] + 1e-9) {
      c.why_not = "B = " + fixed_text(b) + " deg is outside the B limits";
      return c;
    }
  for (std::size_t n = 0; n < pattern.nests.size(); ++n)
    for (double b : pattern.b_deg)
      for (double cc : pattern.c_deg) {
        const Eigen::Vector3d xyz = rtest_commanded_xyz(m, pattern.nests[n], {b * deg, cc * deg});
        for (int k = 0; k < 3; ++k)
          if (xyz[k] < o.travel_min[k] || xyz[k] > o.travel_max[k]) {
            c.why_not = std::string(1, axis[k]) + " = " + fixed_text(xyz[k], 3) + " mm for nest " +
                        std::to_string(n + 1) + " at B " + fixed_text(b) + ", C " + fixed_text(cc) +
                        " deg is outside the travel " + fixed_text(o.travel_min[k]) + ".." +
                        fixed_text(o.travel_max[k]) + " mm";
            return c;
          }
      }
  // The R-test joint fit on the nominal machine's noise-free readings, whitened by sigma.
  RtestSimOptions sim;
  sim.pattern = pattern;
  sim.noise_um = 0.0;
  sim.probe_zero_um = 0.0;
  RtestSession s;
  try {
    s = simulate_rtest(MachineModel::nominal(design_machine(o)), sim).session;
  } catch (const InvalidArgument& e) {
    c.why_not = e.what();
    return c;
  }
  s.machine = m;            // the same readings: the fit is of the BC-trt error model
  s.noise_um = o.noise_um;  // the fit's chi-square scale (observability), as a recorder declares it
  RtestJointOptions fit;
  fit.basis = o.basis;
  fit.whitener = ar1_whitener(s, o.noise_um, o.noise_rho);
  RtestJointIdentification id;
  try {
    id = identify_joint(s, fit);
  } catch (const InvalidArgument& e) {
    c.why_not = e.what();
    return c;
  }
  // Information at the budget: the pattern repeated to fill it (the AR(1) correlation between
  // the end of one run and the start of the next is neglected).
  const double var_scale = c.duration_s / budget;
  const Eigen::Index p = static_cast<Eigen::Index>(id.parameters.size());
  c.sigma.resize(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const ParameterEstimate& e = id.parameters[static_cast<std::size_t>(j)];
    c.names.push_back(e.name);
    c.sigma[j] = e.observable ? std::sqrt(std::max(id.covariance(j, j), 0.0) * var_scale)
                              : std::numeric_limits<double>::infinity();
  }
  const RtestBasis basis = fit.basis.for_machine(m);
  const RtestLayout L = rtest_layout(m, s.setups(), &basis, EffectModel{});
  for (Eigen::Index i = L.errors.offset; i < L.errors.end(); ++i) {
    if (!std::isfinite(c.sigma[i])) {
      c.why_not = c.names[static_cast<std::size_t>(i)] + " is not determined by this pattern";
      return c;
    }
    const double u = 2.0 * c.sigma[i] *
                     (location_error_is_angle(static_cast<int>(i - L.errors.offset))
                          ? o.reference_radius_mm * 1e3
                          : 1e3);
    if (u > c.worst_expanded_um)
      c.worst_expanded_um = u, c.worst_error = c.names[static_cast<std::size_t>(i)];
  }
  // A pattern whose fit holds map coefficients fits a smaller model: its location errors
  // look better only because the maps are assumed zero. Such a pattern is not comparable.
  for (Eigen::Index j = L.errors.end(); j < p; ++j)
    if (!std::isfinite(c.sigma[j])) {
      c.why_not = c.names[static_cast<std::size_t>(j)] +
                  " is not determined: the pose grid is too coarse for the joint fit's basis";
      return c;
    }
  c.feasible = true;
  return c;
}

RtestDesign design_rtest_test(const RtestDesignOptions& o) {
  if (o.nest_radius_mm.empty() || o.nest_height_mm.empty() || o.b_step_deg.empty() ||
      o.c_step_deg.empty())
    throw InvalidArgument(
        "design rtest: --radii, --heights, --b-steps and --c-steps need at least one value each");
  for (double v : o.b_step_deg)
    if (!(v > 0.0)) throw InvalidArgument("design rtest: --b-steps must be > 0 deg");
  for (double v : o.c_step_deg)
    if (!(v > 0.0 && v < 360.0))
      throw InvalidArgument("design rtest: --c-steps must be in (0, 360) deg");
  for (double v : o.nest_radius_mm)
    if (!(v >= 0.0)) throw InvalidArgument("design rtest: --radii must be >= 0 mm");
  if (!(o.noise_um > 0.0)) throw InvalidArgument("design rtest: --noise must be > 0 um");
  if (!(o.noise_rho >= 0.0 && o.noise_rho <= 0.999))
    throw InvalidArgument("design rtest: --rho must be in [0, 0.999]");
  if (!(o.reference_radius_mm > 0.0))
    throw InvalidArgument("design rtest: the reference radius must be > 0 mm");
  if (!(o.base.dwell_s > 0.0)) throw InvalidArgument("design rtest: --dwell must be > 0 s");
  if (!(o.b_limits_deg[0] < o.b_limits_deg[1]))
    throw InvalidArgument("design rtest: --b-limits must be min < max deg");
  if (!(o.time_budget_s >= 0.0) || !std::isfinite(o.time_budget_s))
    throw InvalidArgument("design rtest: --time must be >= 0 s");
  RtestDesign out;
  out.baseline = evaluate_rtest_design(o.base, o, o.time_budget_s);
  out.time_budget_s = o.time_budget_s > 0.0 ? o.time_budget_s : out.baseline.duration_s;
  std::string reasons;
  const auto consider = [&](const RtestPattern& p) {
    RtestDesignCandidate c = evaluate_rtest_design(p, o, out.time_budget_s);
    if (c.feasible && (!out.best.feasible || c.worst_expanded_um < out.best.worst_expanded_um))
      out.best = c;
    if (!c.feasible && reasons.size() < 400) reasons += "; " + c.why_not;
    out.candidates.push_back(std::move(c));
  };
  // Nests at the base grid, then the grid at the best nests.
  for (double r1 : o.nest_radius_mm)
    for (double h1 : o.nest_height_mm)
      for (double r2 : o.nest_radius_mm)
        for (double h2 : o.nest_height_mm) {
          RtestPattern p = o.base;
          p.nests = {Eigen::Vector3d(r1, 0.0, h1), Eigen::Vector3d(0.0, -r2, h2)};
          consider(p);
        }
  if (!out.best.feasible) throw InvalidArgument("design rtest: no nest pair is feasible" + reasons);
  const std::vector<Eigen::Vector3d> nests = out.best.pattern.nests;
  for (double bs : o.b_step_deg)
    for (double cs : o.c_step_deg) {
      RtestPattern p = o.base;
      p.nests = nests;
      p.b_deg = steps(o.b_limits_deg[0], o.b_limits_deg[1], bs);
      p.c_deg = steps(0.0, 360.0 - cs, cs);
      consider(p);
    }
  if (out.baseline.feasible)
    out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal

// ------------------------------------------------------------------ separating two effects

namespace rotacal {

namespace {

// R-test poses as the problem's arrays (machine model, no maps): one set-up per nest.
RtestArrays pose_arrays(std::size_t n) {
  RtestArrays a;
  a.machine = MachineType::BC_trt;
  a.xyz.resize(3, static_cast<Eigen::Index>(n));
  a.nest.resize(3, static_cast<Eigen::Index>(n));
  a.d = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(n));
  return a;
}

// d reading / d parameter at zero errors and zeros (the joint fit's start), in the problem's
// layout (location errors, a probe zero per nest, effects).
Eigen::MatrixXd nominal_rtest_jacobian(const RtestArrays& poses, const EffectModel& fx) {
  const RtestProblem model(poses, nullptr, fx, RtestZeroNames::numbered);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(model.num_parameters());
  Eigen::VectorXd r(model.num_residuals());
  Eigen::MatrixXd J(model.num_residuals(), model.num_parameters());
  model.evaluate(x, r, &J);
  return J;
}

// The added nests: one at each radius, angle and height, with each grid of B and C steps.
std::vector<RtestPattern> separating_nests(const RtestSeparationOptions& o, double dwell) {
  const double deg = M_PI / 180.0;
  std::vector<RtestPattern> out;
  for (double r : o.nest_radius_mm)
    for (double ang : o.nest_angle_deg)
      for (double h : o.nest_height_mm) {
        if (r == 0.0 && ang != o.nest_angle_deg.front()) continue;  // one nest on the axis
        Eigen::Vector3d q(r * std::cos(ang * deg), r * std::sin(ang * deg), h);
        q = (q * 1e9).array().round() / 1e9;  // cos 90 deg is 6e-17, not 0
        for (double bs : o.b_step_deg)
          for (double cs : o.c_step_deg) {
            RtestPattern pat;
            pat.nests = {q};
            pat.b_deg = steps(o.b_limits_deg[0], o.b_limits_deg[1], bs);
            pat.c_deg = steps(0.0, 360.0 - cs, cs);
            pat.dwell_s = dwell;
            out.push_back(pat);
          }
      }
  return out;
}

// The added nest's poses after the session (B outer, C inner, one dwell each), or nothing when
// a pose leaves the travel.
std::optional<RtestArrays> added_poses(const RtestPattern& pat, const RtestSeparationOptions& o,
                                       double t_end) {
  const double deg = M_PI / 180.0;
  RtestArrays a = pose_arrays(pat.b_deg.size() * pat.c_deg.size());
  a.setups = {"added"};
  const Eigen::Vector3d& q = pat.nests[0];
  Eigen::Index i = 0;
  double t = t_end;
  for (double b : pat.b_deg)
    for (double c : pat.c_deg) {
      const RotaryAngles<double> angles{b * deg, c * deg};
      const Eigen::Vector3d xyz = rtest_commanded_xyz(a.machine, q, angles);
      for (int k = 0; k < 3; ++k)
        if (xyz[k] < o.travel_min[k] || xyz[k] > o.travel_max[k]) return std::nullopt;
      a.xyz.col(i) = xyz;
      a.nest.col(i++) = q;
      a.angles.push_back(angles);
      a.time.push_back(t += pat.dwell_s);
      a.setup_of.push_back(0);
    }
  return a;
}

// The chosen nest in words.
std::string describe_candidate(const RtestSeparatingCandidate& c) {
  const RtestPattern& pat = c.added;
  std::ostringstream d;
  d << "a nest at " << point_text(pat.nests[0]) << ", B " << fixed_text(pat.b_deg.front(), 0)
    << ".." << fixed_text(pat.b_deg.back(), 0) << " deg every "
    << fixed_text(pat.b_deg.size() > 1 ? pat.b_deg[1] - pat.b_deg[0] : 0.0, 0) << ", C every "
    << fixed_text(pat.c_deg.size() > 1 ? pat.c_deg[1] - pat.c_deg[0] : 360.0, 0) << " deg, "
    << fixed_text(pat.dwell_s, 1) << " s per pose";
  if (c.repeats > 1.0) d << ", run " << fixed_text(c.repeats, 0) << " times";
  return d.str();
}

}  // namespace

RtestSeparationDesign design_rtest_separation(const RtestSession& session,
                                              const std::vector<Effect>& pair,
                                              const RtestSeparationOptions& o) {
  if (pair.size() != 2 || pair[0] == pair[1])
    throw InvalidArgument("design rtest: --separate needs two different effects (EFFECT,EFFECT)");
  if (session.samples.empty())
    throw InvalidArgument("design rtest: --after: the session has no samples");
  if (session.machine != MachineType::BC_trt)
    throw InvalidArgument("design rtest: --after: the session is not of a BC-trt machine");
  if (o.nest_radius_mm.empty() || o.nest_angle_deg.empty() || o.nest_height_mm.empty() ||
      o.b_step_deg.empty() || o.c_step_deg.empty())
    throw InvalidArgument(
        "design rtest: --radii, --nest-angles, --heights, --b-steps and --c-steps need at least "
        "one value each");
  for (double v : o.b_step_deg)
    if (!(v > 0.0)) throw InvalidArgument("design rtest: --b-steps must be > 0 deg");
  for (double v : o.c_step_deg)
    if (!(v > 0.0 && v < 360.0))
      throw InvalidArgument("design rtest: --c-steps must be in (0, 360) deg");
  if (!(o.max_added_time_s > 0.0) || !std::isfinite(o.max_added_time_s))
    throw InvalidArgument("design rtest: --max-time must be > 0 s");
  if (!(o.max_correlation > 0.0 && o.max_correlation < 1.0))
    throw InvalidArgument("design rtest: --max-correlation must be in (0, 1)");
  if (!(o.noise_um >= 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("design rtest: --noise must be >= 0 um");
  if (!(o.dwell_s >= 0.0) || !std::isfinite(o.dwell_s))
    throw InvalidArgument("design rtest: --dwell must be >= 0 s");
  if (!(o.b_limits_deg[0] < o.b_limits_deg[1]))
    throw InvalidArgument("design rtest: --b-limits must be min < max deg");
  const MachineType m = MachineType::BC_trt;
  RtestSeparationDesign D;
  D.effects = {pair[0].id(), pair[1].id()};
  EffectModel fx;
  fx.effects = pair;
  fx.linear_reference = mean_commanded_xyz(session.samples);
  const double t_end = session.samples.back().time;
  D.motion = table_motion_overlap(m, pair[0], pair[1], o.b_limits_deg, t_end + o.max_added_time_s,
                                  o.reference_radius_mm);

  // The session's poses and noise (the R-test joint fit's residual noise model).
  RtestArrays poses = rtest_arrays(session, "design rtest: --after", false);
  poses.machine = m;
  RtestJointOptions fo;
  fo.noise.noise = NoiseHandling::white;
  const RtestJointIdentification id = identify_joint(session, fo);
  const double w =
      session_weight(o.noise_um, id.noise, id.sigma_um,
                     "design rtest: --after: the session's residuals are zero; give --noise", D);
  // Joint layout: the R-test problem's (location errors, a probe zero per session nest, the
  // pair), then the added nest's probe zero.
  const RtestLayout L = rtest_layout(m, poses.setups, nullptr, fx, RtestZeroNames::numbered);
  const RtestLayout La = rtest_layout(m, {"added"}, nullptr, fx, RtestZeroNames::numbered);
  ParameterLayout joint = L.all;
  const ParameterBlock added_zero = joint.add("zero#added", La.zeros.names, {"mm"}, 3);
  D.names = L.all.names();
  const SeparationProblem S = separation_problem(
      nominal_rtest_jacobian(poses, fx), w, joint, effect_block(L.effects, fx, 0),
      effect_block(L.effects, fx, 1), o.max_correlation, o.max_added_time_s, D);
  const bool search = separation_needed(S, D);
  D.chosen.correlation = D.correlation_before;
  if (!search) return D;
  double dwell = o.dwell_s;
  if (!(dwell > 0.0)) {
    std::vector<double> dt;
    for (std::size_t i = 1; i < session.samples.size(); ++i)
      if (session.samples[i].setup == session.samples[i - 1].setup)
        dt.push_back(session.samples[i].time - session.samples[i - 1].time);
    std::sort(dt.begin(), dt.end());
    dwell = dt.empty() || !(dt[dt.size() / 2] > 0.0) ? RtestPattern{}.dwell_s : dt[dt.size() / 2];
  }

  // Candidates: one nest at each position and grid, its information in the joint layout.
  const std::vector<RtestPattern> patterns = separating_nests(o, dwell);
  std::vector<std::size_t> pattern_of;
  std::vector<AddedInformation> added;
  for (std::size_t k = 0; k < patterns.size(); ++k) {
    const RtestPattern& pat = patterns[k];
    const double duration = static_cast<double>(pat.b_deg.size() * pat.c_deg.size()) * dwell;
    if (duration > o.max_added_time_s) continue;
    std::optional<RtestArrays> nest = added_poses(pat, o, t_end);
    if (!nest) continue;
    const Eigen::MatrixXd Jm =
        in_layout(nominal_rtest_jacobian(*nest, fx), {La.errors, La.zeros, La.effects},
                  {L.errors, added_zero, L.effects}, joint.size());
    added.push_back({duration, Jm.transpose() * Jm * w, true});
    pattern_of.push_back(k);
  }
  D.candidates_tried = static_cast<int>(added.size());
  const SeparationChoice c = search_separation(S, added);
  std::vector<std::string> added_names;
  if (c.index != SeparationChoice::none) {
    RtestSeparatingCandidate& chosen = D.chosen;
    chosen.added = patterns[pattern_of[c.index]];
    chosen.duration_s = added[c.index].duration_s;
    chosen.repeats = c.repeats;
    chosen.correlation = c.correlation;
    chosen.determined = c.determined;
    chosen.description = describe_candidate(chosen);
    added_names = added_zero.names;
  }
  SeparationWording wording;
  wording.added = "added nests";
  wording.seen_by = "";
  wording.closest_note = "";
  finish_separation(S, c, D.chosen.description, D.chosen.duration_s * D.chosen.repeats, added_names,
                    wording, D);
  return D;
}

}  // namespace rotacal
