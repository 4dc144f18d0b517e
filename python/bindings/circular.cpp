// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/circular/{plan,simulate,analysis,diagnosis}.hpp: thin wrappers,
// numpy out.
#include "numpy.hpp"
#include "rotacal/circular/analysis.hpp"
#include "rotacal/circular/diagnosis.hpp"
#include "rotacal/circular/plan.hpp"
#include "rotacal/circular/simulate.hpp"

namespace rotacal::py {

namespace {
Eigen::VectorXd vec(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// The test plan, its runs and its NC program.
void bind_circular_plan(pyb::module_& m) {
  pyb::enum_<CircularPlane>(m, "CircularPlane",
                            "Plane of an ISO 230-4 circular test: (u, v) = XY, YZ, ZX.")
      .value("XY", CircularPlane::XY)
      .value("YZ", CircularPlane::YZ)
      .value("ZX", CircularPlane::ZX);
  pyb::enum_<CircularDirection>(m, "CircularDirection",
                                "ccw: G3, the path angle increases; cw: G2.")
      .value("ccw", CircularDirection::ccw)
      .value("cw", CircularDirection::cw);
  m.def("parse_circular_plane", &parse_circular_plane, pyb::arg("text"));
  m.def("parse_circular_direction", &parse_circular_direction, pyb::arg("text"));
  m.def("circular_label", &circular_label, pyb::arg("plane"), pyb::arg("direction"),
        pyb::arg("feed_mm_per_min"), pyb::arg("with_feed"));

  const CircularTestPlan d;
  pyb::class_<CircularTestPlan>(
      m, "CircularTestPlan", "ISO 230-4 circular tests with the ballbar (mm, deg, mm/min, Hz, s).")
      .def(pyb::init([](MachineType machine, double radius, const Eigen::Vector3d& centre,
                        std::vector<CircularPlane> planes, std::vector<double> feeds_mm_per_min,
                        std::vector<CircularDirection> directions, double start_deg,
                        double span_deg, double run_in_deg, double overshoot_deg,
                        double sample_rate_hz, double remount_s) {
             return CircularTestPlan{machine,
                                     radius,
                                     centre,
                                     std::move(planes),
                                     std::move(feeds_mm_per_min),
                                     std::move(directions),
                                     start_deg,
                                     span_deg,
                                     run_in_deg,
                                     overshoot_deg,
                                     sample_rate_hz,
                                     remount_s};
           }),
           pyb::arg("machine") = d.machine, pyb::arg("radius") = d.radius,
           pyb::arg("centre") = d.centre, pyb::arg("planes") = d.planes,
           pyb::arg("feeds_mm_per_min") = d.feeds_mm_per_min, pyb::arg("directions") = d.directions,
           pyb::arg("start_deg") = d.start_deg, pyb::arg("span_deg") = d.span_deg,
           pyb::arg("run_in_deg") = d.run_in_deg, pyb::arg("overshoot_deg") = d.overshoot_deg,
           pyb::arg("sample_rate_hz") = d.sample_rate_hz, pyb::arg("remount_s") = d.remount_s)
      .def_readwrite("machine", &CircularTestPlan::machine)
      .def_readwrite("radius", &CircularTestPlan::radius)
      .def_readwrite("centre", &CircularTestPlan::centre)
      .def_readwrite("planes", &CircularTestPlan::planes)
      .def_readwrite("feeds_mm_per_min", &CircularTestPlan::feeds_mm_per_min)
      .def_readwrite("directions", &CircularTestPlan::directions)
      .def_readwrite("start_deg", &CircularTestPlan::start_deg)
      .def_readwrite("span_deg", &CircularTestPlan::span_deg)
      .def_readwrite("run_in_deg", &CircularTestPlan::run_in_deg)
      .def_readwrite("overshoot_deg", &CircularTestPlan::overshoot_deg)
      .def_readwrite("sample_rate_hz", &CircularTestPlan::sample_rate_hz)
      .def_readwrite("remount_s", &CircularTestPlan::remount_s);

  pyb::class_<CircularRun>(m, "CircularRun")
      .def_readonly("label", &CircularRun::label)
      .def_readonly("plane", &CircularRun::plane)
      .def_readonly("direction", &CircularRun::direction)
      .def_readonly("feed_mm_per_min", &CircularRun::feed_mm_per_min)
      .def_readonly("run_in_from_deg", &CircularRun::run_in_from_deg)
      .def_readonly("data_from_deg", &CircularRun::data_from_deg)
      .def_readonly("data_to_deg", &CircularRun::data_to_deg)
      .def_readonly("overshoot_to_deg", &CircularRun::overshoot_to_deg)
      .def_readonly("t_start", &CircularRun::t_start)
      .def_property_readonly("time", [](const CircularRun& r) { return vec(r.time); })
      .def_property_readonly("angle_deg", [](const CircularRun& r) { return vec(r.angle_deg); });

  pyb::class_<CircularPlanResult>(m, "CircularPlanResult")
      .def_readonly("plan", &CircularPlanResult::plan)
      .def_readonly("runs", &CircularPlanResult::runs)
      .def("num_samples", &CircularPlanResult::num_samples);

  m.def("plan_circular_test", &plan_circular_test, pyb::arg("plan"),
        "The runs of an ISO 230-4 circular test plan (planes x feeds x directions).");
  m.def("circular_commanded_session", &circular_commanded_session, pyb::arg("plan"),
        "The commanded rotacal-ballbar/1 session of a circular plan (length = L0).");
  m.def("write_circular_nc_program", &write_circular_nc_program, pyb::arg("plan"),
        pyb::arg("dialect"), pyb::arg("options") = NcProgramOptions{},
        "NC program text of a circular plan.");
}

// The linear-axis errors and the simulation.
void bind_circular_simulation(pyb::module_& m) {
  pyb::class_<LinearAxisErrors>(
      m, "LinearAxisErrors",
      "Errors of the linear axes X, Y, Z (mm, rad, s); see circular/simulate.hpp.")
      .def(pyb::init<>())
      .def_readwrite("squareness", &LinearAxisErrors::squareness)
      .def_readwrite("scale", &LinearAxisErrors::scale)
      .def_readwrite("straightness", &LinearAxisErrors::straightness)
      .def_readwrite("backlash", &LinearAxisErrors::backlash)
      .def_readwrite("spike", &LinearAxisErrors::spike)
      .def_readwrite("spike_tau", &LinearAxisErrors::spike_tau)
      .def_readwrite("servo_tau", &LinearAxisErrors::servo_tau)
      .def_readwrite("cyclic_cos", &LinearAxisErrors::cyclic_cos)
      .def_readwrite("cyclic_sin", &LinearAxisErrors::cyclic_sin)
      .def_readwrite("screw_pitch", &LinearAxisErrors::screw_pitch);

  pyb::class_<CircularSimulationOptions>(m, "CircularSimulationOptions")
      .def(pyb::init<>())
      .def_readwrite("errors", &CircularSimulationOptions::errors)
      .def_readwrite("centring_error", &CircularSimulationOptions::centring_error)
      .def_readwrite("length_error", &CircularSimulationOptions::length_error)
      .def_readwrite("noise_um", &CircularSimulationOptions::noise_um)
      .def_readwrite("noise_rho", &CircularSimulationOptions::noise_rho)
      .def_readwrite("seed", &CircularSimulationOptions::seed);

  m.def("simulate_circular", &simulate_circular, pyb::arg("plan"), pyb::arg("options"),
        pyb::call_guard<pyb::gil_scoped_release>(),
        "The session a ballbar records on a machine with linear-axis errors.");
}

// The ISO 230-4 analysis.
void bind_circular_analysis(pyb::module_& m) {
  pyb::class_<CircularRunResult>(m, "CircularRunResult")
      .def_readonly("label", &CircularRunResult::label)
      .def_readonly("plane", &CircularRunResult::plane)
      .def_readonly("direction", &CircularRunResult::direction)
      .def_readonly("feed_mm_per_min", &CircularRunResult::feed_mm_per_min)
      .def_readonly("span_deg", &CircularRunResult::span_deg)
      .def_readonly("n", &CircularRunResult::n)
      .def_readonly("centre_um", &CircularRunResult::centre_um)
      .def_readonly("radius_deviation_um", &CircularRunResult::radius_deviation_um)
      .def_readonly("G_um", &CircularRunResult::G_um)
      .def_readonly("max_um", &CircularRunResult::max_um)
      .def_readonly("min_um", &CircularRunResult::min_um)
      .def_property_readonly("angle_deg",
                             [](const CircularRunResult& r) { return vec(r.angle_deg); })
      .def_property_readonly("radial_um",
                             [](const CircularRunResult& r) { return vec(r.radial_um); });

  pyb::class_<CircularPairResult>(m, "CircularPairResult")
      .def_readonly("plane", &CircularPairResult::plane)
      .def_readonly("feed_mm_per_min", &CircularPairResult::feed_mm_per_min)
      .def_readonly("ccw_label", &CircularPairResult::ccw_label)
      .def_readonly("cw_label", &CircularPairResult::cw_label)
      .def_readonly("G_b_um", &CircularPairResult::G_b_um)
      .def_readonly("H_um", &CircularPairResult::H_um)
      .def_readonly("H_angle_deg", &CircularPairResult::H_angle_deg)
      .def_readonly("common_span_deg", &CircularPairResult::common_span_deg);

  pyb::class_<CircularAnalysis>(m, "CircularAnalysis")
      .def_readonly("ballbar_length", &CircularAnalysis::ballbar_length)
      .def_readonly("runs", &CircularAnalysis::runs)
      .def_readonly("pairs", &CircularAnalysis::pairs)
      .def_readonly("ignored_tests", &CircularAnalysis::ignored_tests);

  m.def("analyze_circular", &analyze_circular, pyb::arg("session"),
        pyb::call_guard<pyb::gil_scoped_release>(),
        "ISO 230-4 circular deviation G per run, G(b) and hysteresis H per cw/ccw pair.");
}

// The circular-test catalogue and diagnosis.
void bind_circular_diagnosis(pyb::module_& m) {
  pyb::class_<CircularEffect>(m, "CircularEffect", "An entry of the circular-test catalogue.")
      .def(pyb::init(&CircularEffect::parse), pyb::arg("id"))
      .def_property_readonly("id", &CircularEffect::id)
      .def_property_readonly("param_names", &CircularEffect::param_names)
      .def_property_readonly("param_units", &CircularEffect::param_units)
      .def_property_readonly("cause", &CircularEffect::cause);
  m.def("circular_catalogue", &circular_catalogue);

  pyb::class_<CircularDiagnosisOptions>(m, "CircularDiagnosisOptions")
      .def(pyb::init<>())
      .def_readwrite("alpha", &CircularDiagnosisOptions::alpha)
      .def_readwrite("min_delta_bic", &CircularDiagnosisOptions::min_delta_bic)
      .def_readwrite("max_findings", &CircularDiagnosisOptions::max_findings)
      .def_readwrite("screw_pitch", &CircularDiagnosisOptions::screw_pitch)
      .def_readwrite("only", &CircularDiagnosisOptions::only)
      .def_readwrite("model_noise", &CircularDiagnosisOptions::model_noise)
      .def_readwrite("cv_blocks", &CircularDiagnosisOptions::cv_blocks)
      .def_readwrite("min_visible_chi2", &CircularDiagnosisOptions::min_visible_chi2);

  pyb::class_<CircularFinding>(m, "CircularFinding")
      .def_readonly("effect", &CircularFinding::effect)
      .def_readonly("cause", &CircularFinding::cause)
      .def_readonly("parameters", &CircularFinding::parameters)
      .def_readonly("gain", &CircularFinding::gain);

  pyb::class_<CircularDiagnosis>(m, "CircularDiagnosis")
      .def_readonly("n", &CircularDiagnosis::n)
      .def_readonly("baseline_rms_um", &CircularDiagnosis::baseline_rms_um)
      .def_readonly("final_rms_um", &CircularDiagnosis::final_rms_um)
      .def_readonly("noise", &CircularDiagnosis::noise)
      .def_readonly("noise_whitened", &CircularDiagnosis::noise_whitened)
      .def_readonly("findings", &CircularDiagnosis::findings)
      .def_readonly("unobservable", &CircularDiagnosis::unobservable)
      .def_readonly("first_round", &CircularDiagnosis::first_round)
      .def_readonly("residuals_mm", &CircularDiagnosis::residuals_mm);

  m.def("diagnose_circular", &diagnose_circular, pyb::arg("session"),
        pyb::arg("options") = CircularDiagnosisOptions{},
        pyb::call_guard<pyb::gil_scoped_release>(),
        "The classic causes the circular runs support, each with parameters, 1-sigma and gain.");
}

}  // namespace

void bind_circular(pyb::module_& m) {
  bind_circular_plan(m);
  bind_circular_simulation(m);
  bind_circular_analysis(m);
  bind_circular_diagnosis(m);
}

}  // namespace rotacal::py
