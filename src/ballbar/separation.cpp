// SPDX-License-Identifier: BSD-3-Clause
// The ballbar's candidates for the design engine (design/separation.hpp): the added tests
// that may separate two effects after a session.
#include "rotacal/design/separation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "length_model.hpp"
#include "rotacal/ballbar/design.hpp"
#include "rotacal/ballbar/problem.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/design/format.hpp"

namespace rotacal {

namespace {

// The candidates: from the session's pivot, one rotary test at each bar length and range (the
// pivot is shared with the session); from a moved pivot (second: true), the sphere tests that
// locate it and one rotary test.
std::vector<std::pair<BallbarSetup, bool>> separating_setups(const BallbarSession& session,
                                                             const std::vector<Effect>& pair,
                                                             const SeparationOptions& o) {
  std::vector<std::pair<BallbarSetup, bool>> cands;
  const MachineType m = session.machine;
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
  for (const Effect& f : pair) motion_pair = motion_pair || f.depends_on_motion();
  if (motion_pair)
    for (double L : o.bar_lengths_mm)
      for (BallbarTest t : {BallbarTest::tangential_c, BallbarTest::tangential_tilt})
        for (const std::vector<double>& feeds :
             {std::vector<double>{1.0}, std::vector<double>{1.0, 2.0}}) {
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

  return cands;
}

// The chosen test in words.
std::string describe(const SeparatingCandidate& c, MachineType m) {
  std::ostringstream d;
  const std::string label = test_label(c.setup.tests.back(), m);
  const bool tilt_test = c.setup.tests.back() == BallbarTest::radial_tilt ||
                         c.setup.tests.back() == BallbarTest::axial_tilt ||
                         c.setup.tests.back() == BallbarTest::tangential_tilt;
  d << label;
  if (tilt_test)
    d << " over " << fixed_text(c.setup.tilt_range_deg[0], 0) << ".."
      << fixed_text(c.setup.tilt_range_deg[1], 0) << " deg";
  if (c.setup.tests.back() == BallbarTest::radial_c)
    d << " (tool circle " << to_string(c.setup.radial_c_side) << ")";
  if (c.setup.directions.size() > 1) d << " ccw and cw";
  if (c.setup.feed_factors.size() > 1) {
    d << " at";
    for (std::size_t k = 0; k < c.setup.feed_factors.size(); ++k)
      d << (k ? ", " : " ") << fixed_text(c.setup.feed_mm_per_min * c.setup.feed_factors[k], 0);
    d << " mm/min";
  }
  d << " with the " << fixed_text(c.setup.ballbar_length, 0) << " mm bar";
  if (c.new_pivot)
    d << ", pivot moved to " << point_text(c.setup.pivot)
      << " (after sphere_xy, sphere_yz, sphere_zx to locate it)";
  else
    d << ", from the session's pivot " << point_text(c.setup.pivot);
  if (c.slow_down > 1.0) d << ", at 1/" << fixed_text(c.slow_down, 0) << " of the feeds";
  return d.str();
}

// Jacobian (mm per unit) of the ballbar lengths of `s` at zero errors and the nominal pivot:
// the joint fit's model without solving it (8 location errors, pivot, effects).
Eigen::MatrixXd nominal_jacobian(const BallbarSession& s, const EffectModel& fx) {
  const BallbarArrays data = ballbar_arrays(s);
  const BallbarLengthModel model(data, fx);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(model.num_parameters());
  model.layout().pivots.of<3>(x) = data.pivot;
  Eigen::VectorXd r(model.num_residuals());
  Eigen::MatrixXd J(model.num_residuals(), model.num_parameters());
  model.evaluate(x, r, &J);
  return J;
}

}  // namespace

SeparationDesign design_ballbar_separation(const BallbarSession& session,
                                           const std::vector<Effect>& pair,
                                           const SeparationOptions& o) {
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
  // model comes from the residuals of the fit. Layout: the ballbar problem's (location errors,
  // the session's pivot, the pair), then a moved pivot's when a candidate moves it.
  JointFitOptions fo;
  fo.effects = fx;
  fo.noise.noise = NoiseHandling::white;
  const BallbarIdentification id = identify_joint(session, fo);
  const double w = session_weight(
      o.noise_um, id.noise, id.sigma_um,
      "design: --after: the session's residuals are zero (commanded data?); give --noise", D);
  const BallbarLayout L = ballbar_layout(m, fx);
  ParameterLayout joint = L.all;
  const ParameterBlock moved_pivot =
      joint.add("pivot#2", {"pivot_x#2", "pivot_y#2", "pivot_z#2"}, {"mm"});
  D.names = L.all.names();
  // The Jacobian at the start point, where the fit judges what it can see (at its solution,
  // location errors of 0.1 mm lend second-order sensitivity that the fit does not use).
  const SeparationProblem S =
      separation_problem(nominal_jacobian(session, fx), w, joint, effect_block(L.effects, fx, 0),
                         effect_block(L.effects, fx, 1), o.max_correlation, o.max_added_time_s, D);
  const bool search = separation_needed(S, D);
  D.chosen.correlation = D.correlation_before;
  if (!search) return D;

  // Each candidate's information in the joint layout; slowing a test down gathers more
  // readings of the same signature, except where the signature depends on the speed: runs at
  // set feeds are taken as planned.
  std::vector<std::pair<BallbarSetup, bool>> cands;
  std::vector<AddedInformation> added;
  for (const auto& [setup, moved] : separating_setups(session, pair, o)) {
    BallbarPlan plan;
    try {
      plan = plan_ballbar_test(setup);
    } catch (const InvalidArgument&) {
      continue;  // e.g. an inside radial C circle the bar cannot reach
    }
    if (!travel_violation(plan, o.travel_min, o.travel_max).empty()) continue;
    const double duration = plan.duration();
    if (duration > o.max_added_time_s) continue;
    BallbarSession cmd = commanded_session(plan);
    for (BallbarSample& smp : cmd.samples) smp.time += t_end;  // after the session
    const Eigen::MatrixXd Jm = in_layout(nominal_jacobian(cmd, fx), {L.errors, L.pivots, L.effects},
                                         {L.errors, moved ? moved_pivot : L.pivots, L.effects},
                                         moved ? joint.size() : L.all.size());
    const bool set_feeds = setup.directions.size() > 1 || setup.feed_factors.size() > 1;
    added.push_back({duration, Jm.transpose() * Jm * w, !set_feeds});
    cands.push_back({setup, moved});
  }
  D.candidates_tried = static_cast<int>(added.size());
  const SeparationChoice c = search_separation(S, added);
  std::vector<std::string> added_names;
  if (c.index != SeparationChoice::none) {
    SeparatingCandidate& chosen = D.chosen;
    chosen.setup = cands[c.index].first;
    chosen.new_pivot = cands[c.index].second;
    chosen.duration_s = added[c.index].duration_s;
    chosen.slow_down = c.repeats;
    chosen.correlation = c.correlation;
    chosen.determined = c.determined;
    chosen.description = describe(chosen, m);
    if (chosen.new_pivot) added_names = moved_pivot.names;
  }
  finish_separation(S, c, D.chosen.description, D.chosen.duration_s * D.chosen.slow_down,
                    added_names, SeparationWording{}, D);
  return D;
}

}  // namespace rotacal
