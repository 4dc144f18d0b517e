// SPDX-License-Identifier: BSD-3-Clause
// The touch probe's candidates for the separation search of the design engine
// (design/separation.hpp): added poses that may separate two effects after a probe session.
#include <algorithm>
#include <cmath>
#include <map>

#include "design_poses.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/design/format.hpp"
#include "rotacal/probe/design.hpp"
#include "rotacal/probe/identify.hpp"

namespace rotacal {

namespace {

struct PoseSet {
  std::vector<RotaryAngles<double>> poses;
  std::string description;
};

// A C sweep at each tilt, a tilt sweep at each rotary angle, and each pose alone.
std::vector<PoseSet> pose_sets(MachineType m, const std::vector<RotaryAngles<double>>& grid) {
  const char tilt = m.description().axis(m.tilt_index()).name,
             rot = m.description().axis(m.rot_index()).name;
  std::map<double, std::vector<RotaryAngles<double>>> by_tilt, by_rot;
  for (const RotaryAngles<double>& a : grid)
    by_tilt[a.tilt].push_back(a), by_rot[a.rot].push_back(a);
  std::vector<PoseSet> out;
  for (const auto& [t, poses] : by_tilt)
    if (poses.size() > 1)
      out.push_back({poses, std::string(1, rot) + " sweep at " + tilt + " " + fixed_text(t, 0) +
                                " deg (" + std::to_string(poses.size()) + " poses)"});
  for (const auto& [r, poses] : by_rot)
    if (poses.size() > 1)
      out.push_back({poses, std::string(1, tilt) + " sweep at " + rot + " " + fixed_text(r, 0) +
                                " deg (" + std::to_string(poses.size()) + " poses)"});
  for (const RotaryAngles<double>& a : grid)
    out.push_back({{a},
                   std::string("the pose ") + tilt + " " + fixed_text(a.tilt, 0) + ", " + rot +
                       " " + fixed_text(a.rot, 0) + " deg"});
  return out;
}

// The session's time per pose: median time between the first touches of successive poses.
double session_pose_time(const ProbeSession& s) {
  std::vector<double> first;
  for (const std::string& p : s.poses()) first.push_back(s.samples[s.indices_of(p).front()].time);
  std::vector<double> dt;
  for (std::size_t i = 1; i < first.size(); ++i) dt.push_back(first[i] - first[i - 1]);
  std::sort(dt.begin(), dt.end());
  return dt.empty() || !(dt[dt.size() / 2] > 0.0) ? ProbePattern{}.pose_dt_s : dt[dt.size() / 2];
}

void check_separation_inputs(const ProbeSession& session, const std::vector<Effect>& pair,
                             const ProbeSeparationOptions& o) {
  if (pair.size() != 2 || pair[0] == pair[1])
    throw InvalidArgument("design probe: --separate needs two different effects (EFFECT,EFFECT)");
  for (const Effect& f : pair) {
    if (!f.applies_to(session.machine))
      throw InvalidArgument("design probe: --separate: effect " + f.id() + " does not exist on " +
                            to_string(session.machine));
    if (f.depends_on_motion())
      throw InvalidArgument("design probe: --separate: " + f.id() +
                            " depends on the motion; the touch probe reads the machine at rest");
  }
  if (session.samples.empty())
    throw InvalidArgument("design probe: --after: the session has no touches");
  if (!(o.tilt_step_deg > 0.0 && o.tilt_step_deg <= 180.0))
    throw InvalidArgument("design probe: --tilt-step must be in (0, 180] deg");
  if (!(o.rot_step_deg > 0.0 && o.rot_step_deg < 360.0))
    throw InvalidArgument("design probe: --rot-step must be in (0, 360) deg");
  if (!(o.max_added_time_s > 0.0) || !std::isfinite(o.max_added_time_s))
    throw InvalidArgument("design probe: --max-time must be > 0 s");
  if (!(o.max_correlation > 0.0 && o.max_correlation < 1.0))
    throw InvalidArgument("design probe: --max-correlation must be in (0, 1)");
  if (!(o.noise_um >= 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("design probe: --noise must be >= 0 um");
  if (!(o.pose_time_s >= 0.0) || !std::isfinite(o.pose_time_s))
    throw InvalidArgument("design probe: --pose-time must be >= 0 s");
  if (!(o.reference_radius_mm > 0.0))
    throw InvalidArgument("design probe: the reference radius must be > 0 mm");
}

}  // namespace

ProbeSeparationDesign design_probe_separation(const ProbeSession& session,
                                              const std::vector<Effect>& pair,
                                              const ProbeSeparationOptions& o) {
  check_separation_inputs(session, pair, o);
  const MachineType m = session.machine;
  ProbeSeparationDesign D;
  D.effects = {pair[0].id(), pair[1].id()};
  EffectModel fx;
  fx.effects = pair;
  fx = centred_on(
      fx, session.samples);  // one linear-axis reference for the session and the added touches
  const double t_end = session.samples.back().time;
  D.motion = table_motion_overlap(m, pair[0], pair[1], probe_design::tilt_range(m),
                                  t_end + o.max_added_time_s, o.reference_radius_mm);

  // The session's information: the probe problem with the pair at the fit's start point, over
  // the white fit's sigma (residuals over n - p: with 120 touches and 19 parameters the noise
  // model's RMS is 8 % low) and its noise model's effective samples. The sphere stays on the
  // table: one layout.
  ProbeFitOptions fo;
  fo.effects = fx;
  fo.noise.noise = NoiseHandling::white;
  const ProbeIdentification id = identify_probe(session, fo);
  const double w = session_weight(
      o.noise_um > 0.0 ? o.noise_um : id.sigma_um, id.noise, id.sigma_um,
      "design probe: --after: the session's residuals are zero (commanded touches?); "
      "give --noise",
      D);
  const ProbeParameterLayout L = ProbeParameterLayout::make(m, fx);
  D.names = L.all.names();
  const SeparationProblem S = separation_problem(
      probe_design::start_jacobian(session, fx), w, L.all, effect_block(L.effects, fx, 0),
      effect_block(L.effects, fx, 1), o.max_correlation, o.max_added_time_s, D);
  const bool search = separation_needed(S, D);
  D.chosen.correlation = D.correlation_before;
  if (!search) return D;

  // Candidates: the session's sphere and the directions of its first pose.
  ProbePattern base;
  base.sphere = session.sphere;
  base.sphere_diameter = session.sphere_diameter;
  base.stylus_diameter = session.stylus_diameter;
  base.directions.clear();
  for (std::size_t i : session.indices_of(session.poses().front()))
    base.directions.push_back(session.samples[i].n);
  base.pose_dt_s = o.pose_time_s > 0.0 ? o.pose_time_s : session_pose_time(session);
  base.touch_dt_s = base.pose_dt_s / static_cast<double>(base.directions.size() + 1);
  const std::vector<PoseSet> sets = pose_sets(
      m,
      probe_design::plannable_poses(m, base, o.tilt_step_deg, o.rot_step_deg, o.program, nullptr));
  std::vector<AddedInformation> added;
  std::vector<std::size_t> set_of;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    ProbePattern P = base;
    P.poses_deg = sets[k].poses;
    const double duration = static_cast<double>(P.poses_deg.size()) * base.pose_dt_s;
    if (duration > o.max_added_time_s) continue;
    try {
      probe_moves(m, P, o.program);  // the turns between the poses too
    } catch (const InvalidArgument&) {
      continue;
    }
    const Eigen::MatrixXd J = probe_design::start_jacobian(
        probe_design::nominal_touches(m, P, t_end + base.pose_dt_s), fx);
    added.push_back({duration, J.transpose() * J * w, true});
    set_of.push_back(k);
  }
  D.candidates_tried = static_cast<int>(added.size());
  const SeparationChoice c = search_separation(S, added);
  if (c.index != SeparationChoice::none) {
    ProbeSeparatingCandidate& chosen = D.chosen;
    chosen.added = base;
    chosen.added.poses_deg = sets[set_of[c.index]].poses;
    chosen.duration_s = added[c.index].duration_s;
    chosen.repeats = c.repeats;
    chosen.correlation = c.correlation;
    chosen.determined = c.determined;
    chosen.description =
        sets[set_of[c.index]].description + ", " + fixed_text(base.pose_dt_s, 0) + " s per pose" +
        (c.repeats > 1.0 ? ", run " + fixed_text(c.repeats, 0) + " times" : std::string());
  }
  SeparationWording wording;
  wording.added = "added pose sets";
  wording.seen_by = " of these poses";
  wording.closest_note = ": another instrument or a second sphere position may";
  finish_separation(S, c, D.chosen.description, D.chosen.duration_s * D.chosen.repeats, {}, wording,
                    D);
  return D;
}

}  // namespace rotacal
