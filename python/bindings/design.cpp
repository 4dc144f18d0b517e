// SPDX-License-Identifier: BSD-3-Clause
// Bindings for the test designs: ballbar/design.hpp, rtest/design.hpp, probe/design.hpp.
#include "rotacal/ballbar/design.hpp"

#include "numpy.hpp"
#include "rotacal/probe/design.hpp"
#include "rotacal/rtest/design.hpp"

namespace rotacal::py {

namespace {

// The members every separation design shares (design/separation.hpp SeparationResult).
template <typename D>
void separation_members(pyb::class_<D>& c) {
  c.def_readonly("effects", &D::effects)
      .def_readonly("motion", &D::motion)
      .def_readonly("names", &D::names)
      .def_readonly("sigma_before", &D::sigma_before)
      .def_readonly("sigma_after", &D::sigma_after)
      .def_readonly("correlation_before", &D::correlation_before)
      .def_readonly("already_separated", &D::already_separated)
      .def_readonly("found", &D::found)
      .def_readonly("candidates_tried", &D::candidates_tried)
      .def_readonly("noise_um", &D::noise_um)
      .def_readonly("effective_per_reading", &D::effective_per_reading)
      .def_readonly("verdict", &D::verdict);
}

// The ballbar set-up design.
void bind_ballbar_design(pyb::module_& m) {
  pyb::class_<BallbarDesignOptions>(m, "BallbarDesignOptions",
                                    "Options of design_ballbar_test (defaults).")
      .def(pyb::init<>())
      .def_readwrite("base", &BallbarDesignOptions::base,
                     "the default set-up: machine, tests, ranges, feeds")
      .def_readwrite("bar_lengths_mm", &BallbarDesignOptions::bar_lengths_mm)
      .def_readwrite("pivot_x_mm", &BallbarDesignOptions::pivot_x_mm)
      .def_readwrite("pivot_z_mm", &BallbarDesignOptions::pivot_z_mm)
      .def_readwrite("travel_min", &BallbarDesignOptions::travel_min,
                     "X, Y, Z, mm (formats.md frame)")
      .def_readwrite("travel_max", &BallbarDesignOptions::travel_max)
      .def_readwrite("time_budget_s", &BallbarDesignOptions::time_budget_s,
                     "0: the default set-up's run time")
      .def_readwrite("sample_rate_hz", &BallbarDesignOptions::sample_rate_hz)
      .def_readwrite("noise_um", &BallbarDesignOptions::noise_um)
      .def_readwrite("noise_rho", &BallbarDesignOptions::noise_rho,
                     "AR(1) coefficient between samples")
      .def_readwrite("reference_radius_mm", &BallbarDesignOptions::reference_radius_mm)
      .def_property(
          "effects_of_concern",
          [](const BallbarDesignOptions& o) { return ids_of(o.effects_of_concern); },
          [](BallbarDesignOptions& o, const std::vector<std::string>& ids) {
            o.effects_of_concern = effects_of(ids);
          });
  pyb::class_<DesignCandidate>(m, "DesignCandidate", "One set-up, evaluated.")
      .def_readonly("setup", &DesignCandidate::setup)
      .def_readonly("feasible", &DesignCandidate::feasible)
      .def_readonly("why_not", &DesignCandidate::why_not)
      .def_readonly("duration_s", &DesignCandidate::duration_s)
      .def_readonly("names", &DesignCandidate::names)
      .def_readonly("sigma", &DesignCandidate::sigma,
                    "predicted 1 sigma at the time budget (mm, rad)")
      .def_readonly("worst_expanded_um", &DesignCandidate::worst_expanded_um)
      .def_readonly("worst_error", &DesignCandidate::worst_error)
      .def_readonly("effect_vs_location", &DesignCandidate::effect_vs_location)
      .def_readonly("effect_vs_effects", &DesignCandidate::effect_vs_effects);
  pyb::class_<BallbarDesign>(m, "BallbarDesign", "The chosen set-up and the default one.")
      .def_readonly("best", &BallbarDesign::best)
      .def_readonly("baseline", &BallbarDesign::baseline)
      .def_readonly("time_budget_s", &BallbarDesign::time_budget_s)
      .def_readonly("ratio", &BallbarDesign::ratio)
      .def_readonly("candidates", &BallbarDesign::candidates);
  m.def(
      "design_ballbar_test",
      [](const BallbarDesignOptions& o) {
        pyb::gil_scoped_release release;
        return design_ballbar_test(o);
      },
      pyb::arg("options"),
      "The pivot and bar length with the smallest predicted uncertainty (ballbar/design.hpp).");
}

// Which effects move the table alike, the added ballbar test that separates two, and
// the joint fit of several sessions.
void bind_ballbar_separation(pyb::module_& m) {
  pyb::class_<TableMotionOverlap>(m, "TableMotionOverlap",
                                  "Whether two effects move the table alike (ballbar/design.hpp).")
      .def_readonly("moves_table_first", &TableMotionOverlap::moves_table_first)
      .def_readonly("moves_table_second", &TableMotionOverlap::moves_table_second)
      .def_readonly("first_is_location", &TableMotionOverlap::first_is_location)
      .def_readonly("second_is_location", &TableMotionOverlap::second_is_location)
      .def_readonly("cosine", &TableMotionOverlap::cosine, "largest cosine of the principal angles")
      .def_readonly("same_motion", &TableMotionOverlap::same_motion,
                    "no instrument can separate them")
      .def_readonly("why", &TableMotionOverlap::why);
  m.def(
      "table_motion_overlap",
      [](MachineType machine, const std::string& a, const std::string& b,
         std::array<double, 2> tilt_limits_deg, double duration_s, double reference_radius_mm) {
        return table_motion_overlap(machine, Effect::parse(a), Effect::parse(b), tilt_limits_deg,
                                    duration_s, reference_radius_mm);
      },
      pyb::arg("machine"), pyb::arg("a"), pyb::arg("b"),
      pyb::arg("tilt_limits_deg") = std::array<double, 2>{-90.0, 90.0},
      pyb::arg("duration_s") = 3600.0, pyb::arg("reference_radius_mm") = 100.0,
      "Compare the table motions of effects a and b (catalogue ids) on a machine.");
  pyb::class_<SeparationOptions>(m, "SeparationOptions",
                                 "Options of design_ballbar_separation (defaults).")
      .def(pyb::init<>())
      .def_readwrite("added", &SeparationOptions::added,
                     "step, feeds and C range of the added test")
      .def_readwrite("bar_lengths_mm", &SeparationOptions::bar_lengths_mm)
      .def_readwrite("pivot_radius_mm", &SeparationOptions::pivot_radius_mm)
      .def_readwrite("pivot_angle_deg", &SeparationOptions::pivot_angle_deg)
      .def_readwrite("pivot_z_mm", &SeparationOptions::pivot_z_mm)
      .def_readwrite("travel_min", &SeparationOptions::travel_min)
      .def_readwrite("travel_max", &SeparationOptions::travel_max)
      .def_readwrite("tilt_limits_deg", &SeparationOptions::tilt_limits_deg)
      .def_readwrite("max_added_time_s", &SeparationOptions::max_added_time_s)
      .def_readwrite("max_correlation", &SeparationOptions::max_correlation)
      .def_readwrite("noise_um", &SeparationOptions::noise_um, "0: the session's residual noise")
      .def_readwrite("reference_radius_mm", &SeparationOptions::reference_radius_mm);
  pyb::class_<SeparatingCandidate>(m, "SeparatingCandidate",
                                   "An added test, evaluated with the session.")
      .def_readonly("setup", &SeparatingCandidate::setup)
      .def_readonly("new_pivot", &SeparatingCandidate::new_pivot)
      .def_readonly("description", &SeparatingCandidate::description)
      .def_readonly("duration_s", &SeparatingCandidate::duration_s)
      .def_readonly("slow_down", &SeparatingCandidate::slow_down)
      .def_readonly("correlation", &SeparatingCandidate::correlation)
      .def_readonly("determined", &SeparatingCandidate::determined);
  auto ballbar_separation = pyb::class_<SeparationDesign>(
      m, "SeparationDesign", "The added test that separates two effects, or why none can.");
  separation_members(ballbar_separation);
  ballbar_separation.def_readonly("chosen", &SeparationDesign::chosen);
  m.def(
      "design_ballbar_separation",
      [](const BallbarSession& session, const std::vector<std::string>& pair,
         const SeparationOptions& o) {
        const EffectModel fx = effects_of(pair);
        pyb::gil_scoped_release release;
        return design_ballbar_separation(session, fx.effects, o);
      },
      pyb::arg("session"), pyb::arg("pair"), pyb::arg("options") = SeparationOptions{},
      "The smallest added test that separates two effects after a session (ballbar/design.hpp).");
}

// The R-test pattern design.
void bind_rtest_design(pyb::module_& m) {
  pyb::class_<RtestDesignOptions>(m, "RtestDesignOptions",
                                  "Options of design_rtest_test (defaults).")
      .def(pyb::init<>())
      .def_readwrite("base", &RtestDesignOptions::base, "the default pattern: nests, grid, dwell")
      .def_readwrite("nest_radius_mm", &RtestDesignOptions::nest_radius_mm)
      .def_readwrite("nest_height_mm", &RtestDesignOptions::nest_height_mm)
      .def_readwrite("b_step_deg", &RtestDesignOptions::b_step_deg)
      .def_readwrite("c_step_deg", &RtestDesignOptions::c_step_deg)
      .def_readwrite("b_limits_deg", &RtestDesignOptions::b_limits_deg)
      .def_readwrite("travel_min", &RtestDesignOptions::travel_min,
                     "X, Y, Z, mm (formats.md frame)")
      .def_readwrite("travel_max", &RtestDesignOptions::travel_max)
      .def_readwrite("time_budget_s", &RtestDesignOptions::time_budget_s,
                     "0: the base pattern's run time")
      .def_readwrite("noise_um", &RtestDesignOptions::noise_um)
      .def_readwrite("noise_rho", &RtestDesignOptions::noise_rho)
      .def_readwrite("reference_radius_mm", &RtestDesignOptions::reference_radius_mm)
      .def_readwrite("basis", &RtestDesignOptions::basis);
  pyb::class_<RtestDesignCandidate>(m, "RtestDesignCandidate", "One R-test pattern, evaluated.")
      .def_readonly("pattern", &RtestDesignCandidate::pattern)
      .def_readonly("feasible", &RtestDesignCandidate::feasible)
      .def_readonly("why_not", &RtestDesignCandidate::why_not)
      .def_readonly("duration_s", &RtestDesignCandidate::duration_s)
      .def_readonly("names", &RtestDesignCandidate::names)
      .def_readonly("sigma", &RtestDesignCandidate::sigma,
                    "predicted 1 sigma at the time budget (mm, rad)")
      .def_readonly("worst_expanded_um", &RtestDesignCandidate::worst_expanded_um)
      .def_readonly("worst_error", &RtestDesignCandidate::worst_error);
  pyb::class_<RtestDesign>(m, "RtestDesign", "The chosen R-test pattern and the default one.")
      .def_readonly("best", &RtestDesign::best)
      .def_readonly("baseline", &RtestDesign::baseline)
      .def_readonly("time_budget_s", &RtestDesign::time_budget_s)
      .def_readonly("ratio", &RtestDesign::ratio)
      .def_readonly("candidates", &RtestDesign::candidates);
  m.def(
      "evaluate_rtest_design",
      [](const RtestPattern& pattern, const RtestDesignOptions& o, double time_budget_s) {
        pyb::gil_scoped_release release;
        return evaluate_rtest_design(pattern, o, time_budget_s);
      },
      pyb::arg("pattern"), pyb::arg("options"), pyb::arg("time_budget_s") = 0.0,
      "One R-test pattern evaluated at a time budget (0: its own run time).");
  m.def(
      "design_rtest_test",
      [](const RtestDesignOptions& o) {
        pyb::gil_scoped_release release;
        return design_rtest_test(o);
      },
      pyb::arg("options"),
      "The R-test nests and pose grid with the smallest predicted uncertainty (rtest/design.hpp).");
}

// The added R-test nest that separates two effects.
void bind_rtest_separation(pyb::module_& m) {
  pyb::class_<RtestSeparationOptions>(m, "RtestSeparationOptions",
                                      "Options of design_rtest_separation (defaults).")
      .def(pyb::init<>())
      .def_readwrite("nest_radius_mm", &RtestSeparationOptions::nest_radius_mm)
      .def_readwrite("nest_angle_deg", &RtestSeparationOptions::nest_angle_deg)
      .def_readwrite("nest_height_mm", &RtestSeparationOptions::nest_height_mm)
      .def_readwrite("b_step_deg", &RtestSeparationOptions::b_step_deg)
      .def_readwrite("c_step_deg", &RtestSeparationOptions::c_step_deg)
      .def_readwrite("b_limits_deg", &RtestSeparationOptions::b_limits_deg)
      .def_readwrite("travel_min", &RtestSeparationOptions::travel_min)
      .def_readwrite("travel_max", &RtestSeparationOptions::travel_max)
      .def_readwrite("dwell_s", &RtestSeparationOptions::dwell_s, "0: the session's")
      .def_readwrite("max_added_time_s", &RtestSeparationOptions::max_added_time_s)
      .def_readwrite("max_correlation", &RtestSeparationOptions::max_correlation)
      .def_readwrite("noise_um", &RtestSeparationOptions::noise_um,
                     "0: the session's residual noise")
      .def_readwrite("reference_radius_mm", &RtestSeparationOptions::reference_radius_mm);
  pyb::class_<RtestSeparatingCandidate>(m, "RtestSeparatingCandidate",
                                        "An added nest, evaluated with the session.")
      .def_readonly("added", &RtestSeparatingCandidate::added)
      .def_readonly("description", &RtestSeparatingCandidate::description)
      .def_readonly("duration_s", &RtestSeparatingCandidate::duration_s)
      .def_readonly("repeats", &RtestSeparatingCandidate::repeats)
      .def_readonly("correlation", &RtestSeparatingCandidate::correlation)
      .def_readonly("determined", &RtestSeparatingCandidate::determined);
  auto rtestballbar_separation = pyb::class_<RtestSeparationDesign>(
      m, "RtestSeparationDesign", "The added nest that separates two effects, or why none can.");
  separation_members(rtestballbar_separation);
  rtestballbar_separation.def_readonly("chosen", &RtestSeparationDesign::chosen);
  m.def(
      "design_rtest_separation",
      [](const RtestSession& session, const std::vector<std::string>& pair,
         const RtestSeparationOptions& o) {
        const EffectModel fx = effects_of(pair);
        pyb::gil_scoped_release release;
        return design_rtest_separation(session, fx.effects, o);
      },
      pyb::arg("session"), pyb::arg("pair"), pyb::arg("options") = RtestSeparationOptions{},
      "The smallest added R-test nest that separates two effects after a session "
      "(rtest/design.hpp).");
}

// Poses (P, 2: tilt, rotary deg) of a probe pattern.
Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> poses_of(const ProbePattern& p) {
  Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> a(
      static_cast<Eigen::Index>(p.poses_deg.size()), 2);
  for (std::size_t i = 0; i < p.poses_deg.size(); ++i)
    a.row(static_cast<Eigen::Index>(i)) << p.poses_deg[i].tilt, p.poses_deg[i].rot;
  return a;
}

// The touch-probe design: poses and touches, and the added poses that separate two effects.
void bind_probe_design(pyb::module_& m) {
  pyb::class_<ProbeDesignOptions>(m, "ProbeDesignOptions",
                                  "Options of design_probe_test (defaults).")
      .def(pyb::init<>())
      .def_readwrite("machine", &ProbeDesignOptions::machine)
      .def_readwrite("sphere", &ProbeDesignOptions::sphere, "nominal centre, table frame, mm")
      .def_readwrite("sphere_diameter", &ProbeDesignOptions::sphere_diameter)
      .def_readwrite("stylus_diameter", &ProbeDesignOptions::stylus_diameter)
      .def_readwrite("touches", &ProbeDesignOptions::touches, "0: the default poses'")
      .def_property(
          "directions", [](const ProbeDesignOptions& o) { return rows_from(o.directions); },
          [](ProbeDesignOptions& o, const Array& a) { o.directions = vectors_of(a, "directions"); },
          "approach directions (K, 3), machine frame; empty: the default pattern's")
      .def_readwrite("tilt_step_deg", &ProbeDesignOptions::tilt_step_deg)
      .def_readwrite("rot_step_deg", &ProbeDesignOptions::rot_step_deg)
      .def_readwrite("noise_um", &ProbeDesignOptions::noise_um)
      .def_readwrite("reference_radius_mm", &ProbeDesignOptions::reference_radius_mm)
      .def_readwrite("touch_directions", &ProbeDesignOptions::touch_directions,
                     "each touch its own direction")
      .def_readwrite("max_contact_angle_deg", &ProbeDesignOptions::max_contact_angle_deg)
      .def_readwrite("contact_step_deg", &ProbeDesignOptions::contact_step_deg)
      .def_property(
          "sphere_candidates",
          [](const ProbeDesignOptions& o) { return rows_from(o.sphere_candidates); },
          [](ProbeDesignOptions& o, const Array& a) {
            o.sphere_candidates = vectors_of(a, "sphere_candidates");
          },
          "other places of the sphere (S, 3), table frame, mm")
      .def_readwrite("sphere_gain", &ProbeDesignOptions::sphere_gain);
  pyb::class_<ProbeSphereTrial>(m, "ProbeSphereTrial", "One place of the sphere the design tried.")
      .def_readonly("sphere", &ProbeSphereTrial::sphere)
      .def_readonly("plannable", &ProbeSphereTrial::plannable)
      .def_readonly("worst_expanded_um", &ProbeSphereTrial::worst_expanded_um)
      .def_readonly("why_not", &ProbeSphereTrial::why_not);
  pyb::class_<ProbeDesignCandidate>(m, "ProbeDesignCandidate", "Poses and touches, evaluated.")
      .def_property_readonly(
          "poses_deg", [](const ProbeDesignCandidate& c) { return poses_of(c.pattern); },
          "pose visits (P, 2): tilt, rotary, deg, in program order")
      .def_property_readonly(
          "directions",
          [](const ProbeDesignCandidate& c) { return rows_from(c.pattern.directions); })
      .def_property_readonly(
          "pose_directions",
          [](const ProbeDesignCandidate& c) {
            std::vector<Rows3> out;
            for (const auto& d : c.pattern.pose_directions) out.push_back(rows_from(d));
            return out;
          },
          "each pose's own directions (K_i, 3); empty: `directions` at every pose")
      .def_property_readonly(
          "sphere", [](const ProbeDesignCandidate& c) { return Eigen::Vector3d(c.pattern.sphere); })
      .def_readonly("feasible", &ProbeDesignCandidate::feasible)
      .def_readonly("why_not", &ProbeDesignCandidate::why_not)
      .def_readonly("touches", &ProbeDesignCandidate::touches)
      .def_readonly("names", &ProbeDesignCandidate::names)
      .def_readonly("sigma", &ProbeDesignCandidate::sigma, "predicted 1 sigma (mm, rad); inf: held")
      .def_readonly("worst_expanded_um", &ProbeDesignCandidate::worst_expanded_um)
      .def_readonly("worst_error", &ProbeDesignCandidate::worst_error)
      .def_readonly("undetermined", &ProbeDesignCandidate::undetermined);
  pyb::class_<ProbeDesign>(m, "ProbeDesign",
                           "The designed poses and the default ones at the same touches.")
      .def_readonly("best", &ProbeDesign::best)
      .def_readonly("baseline", &ProbeDesign::baseline)
      .def_readonly("touches", &ProbeDesign::touches)
      .def_readonly("ratio", &ProbeDesign::ratio)
      .def_readonly("poses_tried", &ProbeDesign::poses_tried)
      .def_readonly("touches_tried", &ProbeDesign::touches_tried)
      .def_readonly("refused", &ProbeDesign::refused)
      .def_readonly("sphere", &ProbeDesign::sphere)
      .def_readonly("spheres", &ProbeDesign::spheres);
  m.def(
      "design_probe_test",
      [](const ProbeDesignOptions& o) {
        pyb::gil_scoped_release release;
        return design_probe_test(o);
      },
      pyb::arg("options"),
      "The poses and touches with the smallest predicted uncertainty (probe/design.hpp).");
  pyb::class_<ProbeSeparationOptions>(m, "ProbeSeparationOptions",
                                      "Options of design_probe_separation (defaults).")
      .def(pyb::init<>())
      .def_readwrite("tilt_step_deg", &ProbeSeparationOptions::tilt_step_deg)
      .def_readwrite("rot_step_deg", &ProbeSeparationOptions::rot_step_deg)
      .def_readwrite("pose_time_s", &ProbeSeparationOptions::pose_time_s, "0: the session's")
      .def_readwrite("max_added_time_s", &ProbeSeparationOptions::max_added_time_s)
      .def_readwrite("max_correlation", &ProbeSeparationOptions::max_correlation)
      .def_readwrite("noise_um", &ProbeSeparationOptions::noise_um,
                     "0: the session's residual noise")
      .def_readwrite("reference_radius_mm", &ProbeSeparationOptions::reference_radius_mm);
  pyb::class_<ProbeSeparatingCandidate>(m, "ProbeSeparatingCandidate",
                                        "Added poses, evaluated with the session.")
      .def_property_readonly("poses_deg",
                             [](const ProbeSeparatingCandidate& c) { return poses_of(c.added); })
      .def_property_readonly(
          "directions",
          [](const ProbeSeparatingCandidate& c) { return rows_from(c.added.directions); })
      .def_readonly("description", &ProbeSeparatingCandidate::description)
      .def_readonly("duration_s", &ProbeSeparatingCandidate::duration_s)
      .def_readonly("repeats", &ProbeSeparatingCandidate::repeats)
      .def_readonly("correlation", &ProbeSeparatingCandidate::correlation)
      .def_readonly("determined", &ProbeSeparatingCandidate::determined);
  auto probeballbar_separation = pyb::class_<ProbeSeparationDesign>(
      m, "ProbeSeparationDesign", "The added poses that separate two effects, or why none can.");
  separation_members(probeballbar_separation);
  probeballbar_separation.def_readonly("chosen", &ProbeSeparationDesign::chosen);
  m.def(
      "design_probe_separation",
      [](const ProbeSession& session, const std::vector<std::string>& pair,
         const ProbeSeparationOptions& o) {
        const EffectModel fx = effects_of(pair);
        pyb::gil_scoped_release release;
        return design_probe_separation(session, fx.effects, o);
      },
      pyb::arg("session"), pyb::arg("pair"), pyb::arg("options") = ProbeSeparationOptions{},
      "The smallest added set of poses that separates two effects after a touch-probe session "
      "(probe/design.hpp).");
}

}  // namespace

void bind_design(pyb::module_& m) {
  bind_ballbar_design(m);
  bind_ballbar_separation(m);
  bind_rtest_design(m);
  bind_rtest_separation(m);
}

// After bind_probe: its signatures name ProbeSession.
void bind_probe_design_module(pyb::module_& m) { bind_probe_design(m); }

}  // namespace rotacal::py
