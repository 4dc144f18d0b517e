// SPDX-License-Identifier: BSD-3-Clause
// Test design of the touch probe (probe/design.hpp): the candidate poses and their
// information, handed to the design engine (design/allocation.hpp).
#include "rotacal/probe/design.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "design_poses.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/design/allocation.hpp"
#include "rotacal/design/format.hpp"
#include "rotacal/probe/problem.hpp"

namespace rotacal {

namespace {

using probe_design::plannable_poses;

ProbePattern base_pattern(const ProbeDesignOptions& o) {
  ProbePattern P = default_probe_pattern(o.machine);
  P.sphere = o.sphere;
  P.sphere_diameter = o.sphere_diameter;
  P.stylus_diameter = o.stylus_diameter;
  if (!o.directions.empty()) P.directions = o.directions;
  return P;
}

// The candidates at one place of the sphere: a plannable grid pose with the directions of one
// run (touch by touch: one direction; else the pattern's), the information of one run (fit
// units, 1 / mm^2 weights), and what they determine together.
struct Candidates {
  ProbeParameterLayout layout;
  Eigen::Vector3d sphere;
  std::vector<RotaryAngles<double>> poses;         // the plannable poses
  std::vector<std::size_t> pose_of;                // per candidate
  std::vector<std::vector<Eigen::Vector3d>> dirs;  // per candidate: its touches' directions
  std::vector<Eigen::MatrixXd> info;
  std::vector<std::string> refused;
  Eigen::VectorXd plausible,
      scale;  // per parameter; per location error (um of 2 sigma per mm or rad)
  std::vector<bool> determinable;      // per location error
  std::vector<bool> determinable_all;  // per parameter: by all candidates together
};

// Fisher information of the touches of P, J^T J / sigma^2, and J.
Eigen::MatrixXd touch_jacobian(const ProbeDesignOptions& o, const ProbePattern& P) {
  return probe_design::start_jacobian(probe_design::nominal_touches(o.machine, P), EffectModel{});
}

// Touch by touch: each grid pose's contact directions that probe_moves accepts one by one.
void touch_candidates(const ProbeDesignOptions& o, const ProbePattern& base, Candidates& c) {
  for (const RotaryAngles<double>& pose :
       probe_design::pose_grid(o.machine, o.tilt_step_deg, o.rot_step_deg)) {
    ProbePattern one = base;
    one.poses_deg = {pose};
    std::string why;
    bool any = false;
    for (const Eigen::Vector3d& n : probe_design::contact_directions(
             o.machine, pose, o.max_contact_angle_deg, o.contact_step_deg)) {
      one.directions = {n};
      try {
        probe_moves(o.machine, one, o.program);
      } catch (const InvalidArgument& e) {
        why = e.what();
        continue;
      }
      if (!any) c.poses.push_back(pose), any = true;
      c.pose_of.push_back(c.poses.size() - 1);
      c.dirs.push_back({n});
    }
    if (!any)
      c.refused.push_back("tilt " + fixed_text(pose.tilt, 1) + ", rotary " +
                          fixed_text(pose.rot, 1) + " deg: " + why);
  }
}

Candidates candidates(const ProbeDesignOptions& o, const Eigen::Vector3d& sphere) {
  Candidates c;
  c.sphere = sphere;
  c.layout = ProbeParameterLayout::make(o.machine, EffectModel{});
  ProbePattern P = base_pattern(o);
  P.sphere = sphere;
  if (o.touch_directions) {
    touch_candidates(o, P, c);
  } else {
    c.poses = plannable_poses(o.machine, P, o.tilt_step_deg, o.rot_step_deg, o.program, &c.refused);
    for (std::size_t k = 0; k < c.poses.size(); ++k)
      c.pose_of.push_back(k), c.dirs.push_back(P.directions);
  }
  if (c.poses.empty())
    throw InvalidArgument("design probe: no candidate pose can be planned" +
                          (c.refused.empty() ? std::string() : " (" + c.refused.front() + ")"));
  // One pattern of every candidate's touches: pose k touched along its candidates' directions.
  P.poses_deg = c.poses;
  P.pose_directions.assign(c.poses.size(), {});
  for (std::size_t i = 0; i < c.dirs.size(); ++i)
    for (const Eigen::Vector3d& n : c.dirs[i]) P.pose_directions[c.pose_of[i]].push_back(n);
  const Eigen::MatrixXd J = touch_jacobian(o, P);
  const double w = 1.0 / (o.noise_um * o.noise_um * 1e-6);
  const Eigen::Index p = c.layout.size();
  Eigen::MatrixXd all = Eigen::MatrixXd::Zero(p, p);
  // The rows of J follow the poses, and within a pose its candidates in order.
  std::vector<Eigen::Index> first(c.poses.size() + 1, 0);
  for (std::size_t k = 0; k < c.poses.size(); ++k)
    first[k + 1] = first[k] + static_cast<Eigen::Index>(P.pose_directions[k].size());
  std::vector<Eigen::Index> next(first.begin(), first.end() - 1);
  for (std::size_t i = 0; i < c.dirs.size(); ++i) {
    const Eigen::Index K = static_cast<Eigen::Index>(c.dirs[i].size());
    const auto rows = J.middleRows(next[c.pose_of[i]], K);
    next[c.pose_of[i]] += K;
    c.info.push_back(rows.transpose() * rows * w);
    all += c.info.back();
  }
  const std::vector<std::string> units = c.layout.all.units();
  c.plausible.resize(p);
  for (Eigen::Index j = 0; j < p; ++j)
    c.plausible[j] = plausible_magnitude(units[static_cast<std::size_t>(j)]);
  c.scale.resize(c.layout.errors.size);
  for (Eigen::Index j = 0; j < c.layout.errors.size; ++j)
    c.scale[j] =
        2.0 * 1e3 * (location_error_is_angle(static_cast<int>(j)) ? o.reference_radius_mm : 1.0);
  const Inverted every = invert_information(all, c.plausible, 1.0);
  c.determinable_all = every.determined;
  for (Eigen::Index j = 0; j < c.layout.errors.size; ++j)
    c.determinable.push_back(
        every.determined[static_cast<std::size_t>(c.layout.errors.offset + j)]);
  return c;
}

// A pattern's predicted uncertainty from its information I (at its touches).
ProbeDesignCandidate judge(const ProbePattern& P, const Eigen::MatrixXd& I, const Candidates& c,
                           int touches) {
  ProbeDesignCandidate out;
  out.pattern = P;
  out.touches = touches;
  out.names = c.layout.all.names();
  const Inverted inv = invert_information(I, c.plausible, 1.0);
  out.sigma = inv.sigma;
  const DesignUncertainty u = design_uncertainty(inv, c.layout.errors, c.scale, c.determinable);
  std::string missing;
  for (Eigen::Index j = 0; j < c.layout.errors.size; ++j) {
    const std::string& name = out.names[static_cast<std::size_t>(c.layout.errors.offset + j)];
    if (!c.determinable[static_cast<std::size_t>(j)])
      out.undetermined.push_back(name);
    else if (!inv.determined[static_cast<std::size_t>(c.layout.errors.offset + j)])
      missing += (missing.empty() ? "" : ", ") + name;
  }
  // The sphere's centre (and any other parameter beside the location errors) that the candidates
  // determine but these poses do not is held by the fit, and the errors' sigmas would take it
  // as known. (What no candidate determines, as the tool length with the sphere's z on a head,
  // is a choice of origin, which moves no location error.)
  const auto e0 = static_cast<std::size_t>(c.layout.errors.offset),
             e1 = e0 + static_cast<std::size_t>(c.layout.errors.size);
  bool nuisance_missing = false;
  for (std::size_t j = 0; j < out.names.size(); ++j) {
    if (j >= e0 && j < e1) continue;
    if (c.determinable_all[j] && !inv.determined[j])
      missing += (missing.empty() ? "" : ", ") + out.names[j], nuisance_missing = true;
  }
  if (!u.feasible || nuisance_missing) {
    out.why_not = missing + " not determined by these poses";
    return out;
  }
  out.feasible = true;
  out.worst_expanded_um = u.worst;
  if (u.worst_index >= 0) out.worst_error = out.names[static_cast<std::size_t>(u.worst_index)];
  return out;
}

// The pattern evaluated at `touches` (0: its own), after checking that it can be planned.
ProbeDesignCandidate evaluate(const ProbePattern& P, const ProbeDesignOptions& o,
                              const Candidates& c, int touches) {
  ProbeDesignCandidate out;
  out.pattern = P;
  try {
    probe_moves(o.machine, P, o.program);
  } catch (const InvalidArgument& e) {
    out.why_not = e.what();
    return out;
  }
  const int own = static_cast<int>(P.touch_count());
  if (touches <= 0) touches = own;
  const Eigen::MatrixXd J = touch_jacobian(o, P);
  const double w = 1.0 / (o.noise_um * o.noise_um * 1e-6);
  return judge(P, J.transpose() * J * (w * touches / own), c, touches);
}

void check(const ProbeDesignOptions& o) {
  if (!(o.touches == 0 || (o.touches >= 3 && o.touches <= 100000)))
    throw InvalidArgument("design probe: --touches must be in 3..100000 (0: the default poses')");
  if (!(o.tilt_step_deg > 0.0 && o.tilt_step_deg <= 180.0))
    throw InvalidArgument("design probe: --tilt-step must be in (0, 180] deg");
  if (!(o.rot_step_deg > 0.0 && o.rot_step_deg < 360.0))
    throw InvalidArgument("design probe: --rot-step must be in (0, 360) deg");
  if (!(o.noise_um > 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("design probe: --noise must be > 0 um");
  if (!(o.reference_radius_mm > 0.0) || !std::isfinite(o.reference_radius_mm))
    throw InvalidArgument("design probe: the reference radius must be > 0 mm");
  if (!(o.sphere_diameter > 0.0) || !(o.stylus_diameter > 0.0))
    throw InvalidArgument("design probe: --sphere-diameter and --stylus-diameter must be > 0 mm");
  for (const Eigen::Vector3d& n : o.directions)
    if (!(n.norm() > 0.0) || !n.allFinite())
      throw InvalidArgument("design probe: a zero approach direction");
  if (!(o.max_contact_angle_deg > 0.0 && o.max_contact_angle_deg <= 90.0))
    throw InvalidArgument("design probe: --max-contact-angle must be in (0, 90] deg");
  if (!(o.contact_step_deg > 0.0 && o.contact_step_deg <= 90.0))
    throw InvalidArgument("design probe: the contact step must be in (0, 90] deg");
  if (!(o.sphere_gain >= 0.0 && o.sphere_gain < 1.0))
    throw InvalidArgument("design probe: the sphere gain must be in [0, 1)");
  for (const Eigen::Vector3d& s : o.sphere_candidates)
    if (!s.allFinite())
      throw InvalidArgument("design probe: --sphere-candidates: a place that is not a number");
}

// The designed pattern of `counts` runs of the candidates, in program order: by tilt, the rotary
// angle back and forth (fewer turns). Touch by touch, a pose is visited once along the
// directions of its chosen touches; else each run is a visit along the pattern's directions.
ProbePattern designed_pattern(const ProbePattern& base, const Candidates& c,
                              const std::vector<int>& counts, bool touch_by_touch) {
  std::vector<std::vector<Eigen::Vector3d>> dirs(c.poses.size());
  std::vector<int> visits(c.poses.size(), 0);
  for (std::size_t i = 0; i < counts.size(); ++i)
    for (int r = 0; r < counts[i]; ++r) {
      dirs[c.pose_of[i]].insert(dirs[c.pose_of[i]].end(), c.dirs[i].begin(), c.dirs[i].end());
      visits[c.pose_of[i]] = touch_by_touch ? 1 : visits[c.pose_of[i]] + 1;
    }
  std::map<double, std::vector<std::size_t>> by_tilt;
  for (std::size_t k = 0; k < c.poses.size(); ++k)
    if (visits[k] > 0) by_tilt[c.poses[k].tilt].push_back(k);
  ProbePattern out = base;
  out.sphere = c.sphere;
  out.poses_deg.clear();
  bool forward = true;
  for (auto& [tilt, ks] : by_tilt) {
    std::sort(ks.begin(), ks.end(), [&](std::size_t a, std::size_t b) {
      return forward ? c.poses[a].rot < c.poses[b].rot : c.poses[a].rot > c.poses[b].rot;
    });
    for (std::size_t k : ks) {
      out.poses_deg.insert(out.poses_deg.end(), static_cast<std::size_t>(visits[k]), c.poses[k]);
      if (touch_by_touch) out.pose_directions.push_back(dirs[k]);
    }
    forward = !forward;
  }
  return out;
}

// The design at the sphere of candidates c: the engine's allocation of `touches`, checked as a
// whole program.
ProbeDesignCandidate design_at(const ProbeDesignOptions& o, const Candidates& c, int touches,
                               int per_run) {
  AllocationProblem ap;
  ap.candidates = c.info;
  ap.runs = touches / per_run;
  ap.target = c.layout.errors;
  ap.scale = c.scale;
  ap.plausible = c.plausible;
  const Allocation a = allocate_runs(ap);
  const ProbePattern best = designed_pattern(base_pattern(o), c, a.counts, o.touch_directions);
  try {
    probe_moves(o.machine, best, o.program);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(
        std::string("design probe: the designed poses cannot be planned together: ") + e.what());
  }
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(c.layout.size(), c.layout.size());
  for (std::size_t k = 0; k < c.info.size(); ++k) I += a.counts[k] * c.info[k];
  return judge(best, I, c, ap.runs * per_run);
}

}  // namespace

ProbeDesignCandidate evaluate_probe_pattern(const ProbePattern& pattern,
                                            const ProbeDesignOptions& o, int touches) {
  check(o);
  return evaluate(pattern, o, candidates(o, o.sphere), touches);
}

ProbeDesign design_probe_test(const ProbeDesignOptions& o) {
  check(o);
  const Candidates c0 = candidates(o, o.sphere);
  ProbeDesign out;
  const ProbePattern base = base_pattern(o);
  const int K = o.touch_directions ? 1 : static_cast<int>(base.directions.size());
  out.touches = o.touches > 0 ? o.touches : static_cast<int>(base.touch_count());
  if (out.touches < K || out.touches % K != 0)
    throw InvalidArgument("design probe: --touches " + std::to_string(out.touches) +
                          " is not a multiple of the " + std::to_string(K) + " touches of a pose");
  out.baseline = evaluate(base, o, c0, out.touches);
  const auto infeasible = [&](const ProbeDesignCandidate& d) {
    return InvalidArgument("design probe: --touches " + std::to_string(out.touches) + " (" +
                           std::to_string(out.touches / K) + (K == 1 ? " touches" : " poses") +
                           "): " + d.why_not + "; give more touches");
  };
  out.best = design_at(o, c0, out.touches, K);
  if (!out.best.feasible) throw infeasible(out.best);
  const Candidates* chosen = &c0;
  out.spheres.push_back({o.sphere, true, out.best.worst_expanded_um, ""});
  // The other places of the sphere: the best taken when it pays by sphere_gain.
  Candidates moved;
  for (const Eigen::Vector3d& s : o.sphere_candidates) {
    ProbeSphereTrial t{s, false, 0.0, ""};
    try {
      Candidates c = candidates(o, s);
      const ProbeDesignCandidate d = design_at(o, c, out.touches, K);
      if (!d.feasible) throw infeasible(d);
      t.plannable = true;
      t.worst_expanded_um = d.worst_expanded_um;
      const double now = chosen == &c0 ? (1.0 - o.sphere_gain) * out.best.worst_expanded_um
                                       : out.best.worst_expanded_um;
      if (d.worst_expanded_um < now) out.best = d, moved = std::move(c), chosen = &moved;
    } catch (const InvalidArgument& e) {
      t.why_not = e.what();
    }
    out.spheres.push_back(t);
  }
  out.sphere = chosen->sphere;
  out.poses_tried = static_cast<int>(chosen->poses.size());
  out.touches_tried = static_cast<int>(chosen->info.size());
  const std::size_t shown = std::min<std::size_t>(chosen->refused.size(), 5);
  out.refused.assign(chosen->refused.begin(),
                     chosen->refused.begin() + static_cast<std::ptrdiff_t>(shown));
  if (out.baseline.feasible)
    out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal
