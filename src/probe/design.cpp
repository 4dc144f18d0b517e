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

// The candidate poses, the information of one visit of each (fit units, 1 / mm^2 weights),
// and what they determine together.
struct Candidates {
  ProbeParameterLayout layout;
  std::vector<RotaryAngles<double>> poses;
  std::vector<Eigen::MatrixXd> info;
  std::vector<std::string> refused;
  Eigen::VectorXd plausible, scale;  // per parameter; per location error (um of 2 sigma per mm or rad)
  std::vector<bool> determinable;    // per location error
};

// Fisher information of the touches of P, J^T J / sigma^2, and J.
Eigen::MatrixXd touch_jacobian(const ProbeDesignOptions& o, const ProbePattern& P) {
  return probe_design::start_jacobian(probe_design::nominal_touches(o.machine, P), EffectModel{});
}

Candidates candidates(const ProbeDesignOptions& o) {
  Candidates c;
  c.layout = ProbeParameterLayout::make(o.machine, EffectModel{});
  ProbePattern P = base_pattern(o);
  c.poses = plannable_poses(o.machine, P, o.tilt_step_deg, o.rot_step_deg, o.program, &c.refused);
  if (c.poses.empty())
    throw InvalidArgument("design probe: no candidate pose can be planned" +
                          (c.refused.empty() ? std::string() : " (" + c.refused.front() + ")"));
  P.poses_deg = c.poses;
  const Eigen::MatrixXd J = touch_jacobian(o, P);
  const Eigen::Index K = static_cast<Eigen::Index>(P.directions.size());
  const double w = 1.0 / (o.noise_um * o.noise_um * 1e-6);
  const Eigen::Index p = c.layout.size();
  Eigen::MatrixXd all = Eigen::MatrixXd::Zero(p, p);
  for (std::size_t k = 0; k < c.poses.size(); ++k) {
    const auto rows = J.middleRows(static_cast<Eigen::Index>(k) * K, K);
    c.info.push_back(rows.transpose() * rows * w);
    all += c.info.back();
  }
  const std::vector<std::string> units = c.layout.all.units();
  c.plausible.resize(p);
  for (Eigen::Index j = 0; j < p; ++j) c.plausible[j] = plausible_magnitude(units[static_cast<std::size_t>(j)]);
  c.scale.resize(c.layout.errors.size);
  for (Eigen::Index j = 0; j < c.layout.errors.size; ++j)
    c.scale[j] = 2.0 * 1e3 * (location_error_is_angle(static_cast<int>(j)) ? o.reference_radius_mm : 1.0);
  const Inverted every = invert_information(all, c.plausible, 1.0);
  for (Eigen::Index j = 0; j < c.layout.errors.size; ++j)
    c.determinable.push_back(every.determined[static_cast<std::size_t>(c.layout.errors.offset + j)]);
  return c;
}

// A pattern's predicted uncertainty from its information I (at its touches).
ProbeDesignCandidate judge(const ProbePattern& P, const Eigen::MatrixXd& I, const Candidates& c, int touches) {
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
    if (!c.determinable[static_cast<std::size_t>(j)]) out.undetermined.push_back(name);
    else if (!inv.determined[static_cast<std::size_t>(c.layout.errors.offset + j)])
      missing += (missing.empty() ? "" : ", ") + name;
  }
  if (!u.feasible) {
    out.why_not = missing + " not determined by these poses";
    return out;
  }
  out.feasible = true;
  out.worst_expanded_um = u.worst;
  if (u.worst_index >= 0) out.worst_error = out.names[static_cast<std::size_t>(u.worst_index)];
  return out;
}

// The pattern evaluated at `touches` (0: its own), after checking that it can be planned.
ProbeDesignCandidate evaluate(const ProbePattern& P, const ProbeDesignOptions& o, const Candidates& c, int touches) {
  ProbeDesignCandidate out;
  out.pattern = P;
  try {
    probe_moves(o.machine, P, o.program);
  } catch (const InvalidArgument& e) {
    out.why_not = e.what();
    return out;
  }
  const int own = static_cast<int>(P.poses_deg.size() * P.directions.size());
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
  if (!(o.noise_um > 0.0) || !std::isfinite(o.noise_um)) throw InvalidArgument("design probe: --noise must be > 0 um");
  if (!(o.reference_radius_mm > 0.0) || !std::isfinite(o.reference_radius_mm))
    throw InvalidArgument("design probe: the reference radius must be > 0 mm");
  if (!(o.sphere_diameter > 0.0) || !(o.stylus_diameter > 0.0))
    throw InvalidArgument("design probe: --sphere-diameter and --stylus-diameter must be > 0 mm");
  for (const Eigen::Vector3d& n : o.directions)
    if (!(n.norm() > 0.0) || !n.allFinite()) throw InvalidArgument("design probe: a zero approach direction");
}

// Pose visits in program order: by tilt, the rotary angle back and forth (fewer turns).
std::vector<RotaryAngles<double>> ordered_visits(const std::vector<RotaryAngles<double>>& poses,
                                                 const std::vector<int>& counts) {
  std::map<double, std::vector<std::size_t>> by_tilt;
  for (std::size_t k = 0; k < poses.size(); ++k)
    if (counts[k] > 0) by_tilt[poses[k].tilt].push_back(k);
  std::vector<RotaryAngles<double>> out;
  bool forward = true;
  for (auto& [tilt, ks] : by_tilt) {
    std::sort(ks.begin(), ks.end(), [&](std::size_t a, std::size_t b) {
      return forward ? poses[a].rot < poses[b].rot : poses[a].rot > poses[b].rot;
    });
    for (std::size_t k : ks) out.insert(out.end(), static_cast<std::size_t>(counts[k]), poses[k]);
    forward = !forward;
  }
  return out;
}

}  // namespace

ProbeDesignCandidate evaluate_probe_pattern(const ProbePattern& pattern, const ProbeDesignOptions& o, int touches) {
  check(o);
  return evaluate(pattern, o, candidates(o), touches);
}

ProbeDesign design_probe_test(const ProbeDesignOptions& o) {
  check(o);
  const Candidates c = candidates(o);
  ProbeDesign out;
  out.poses_tried = static_cast<int>(c.poses.size());
  const std::size_t shown = std::min<std::size_t>(c.refused.size(), 5);
  out.refused.assign(c.refused.begin(), c.refused.begin() + static_cast<std::ptrdiff_t>(shown));
  const ProbePattern base = base_pattern(o);
  const int K = static_cast<int>(base.directions.size());
  out.touches = o.touches > 0 ? o.touches : static_cast<int>(base.poses_deg.size()) * K;
  if (out.touches < K || out.touches % K != 0)
    throw InvalidArgument("design probe: --touches " + std::to_string(out.touches) + " is not a multiple of the " +
                          std::to_string(K) + " touches of a pose");
  out.baseline = evaluate(base, o, c, out.touches);

  AllocationProblem ap;
  ap.candidates = c.info;
  ap.runs = out.touches / K;
  ap.target = c.layout.errors;
  ap.scale = c.scale;
  ap.plausible = c.plausible;
  const Allocation a = allocate_runs(ap);
  ProbePattern best = base;
  best.poses_deg = ordered_visits(c.poses, a.counts);
  try {
    probe_moves(o.machine, best, o.program);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("design probe: the designed poses cannot be planned together: ") + e.what());
  }
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(c.layout.size(), c.layout.size());
  for (std::size_t k = 0; k < c.poses.size(); ++k) I += a.counts[k] * c.info[k];
  out.best = judge(best, I, c, ap.runs * K);
  if (!out.best.feasible)
    throw InvalidArgument("design probe: --touches " + std::to_string(out.touches) + " (" +
                          std::to_string(ap.runs) + " poses): " + out.best.why_not + "; give more touches");
  if (out.baseline.feasible) out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal
