// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/ballbar/{plan,nc_program,chain_runs}.hpp: thin wrappers, numpy out.
#include "numpy.hpp"
#include "rotacal/ballbar/chain_runs.hpp"
#include "rotacal/ballbar/nc_program.hpp"
#include "rotacal/ballbar/plan.hpp"

namespace rotacal::py {

namespace {

// The tests, directions, segment kinds and dialects, and their labels.
void bind_ballbar_tests(pyb::module_& m) {
  pyb::enum_<BallbarTest>(m, "BallbarTest",
                          "Tests of the single set-up method; ``*_tilt`` are A or B by machine.")
      .value("sphere_xy", BallbarTest::sphere_xy)
      .value("sphere_yz", BallbarTest::sphere_yz)
      .value("sphere_zx", BallbarTest::sphere_zx)
      .value("radial_tilt", BallbarTest::radial_tilt)
      .value("axial_tilt", BallbarTest::axial_tilt)
      .value("radial_c", BallbarTest::radial_c)
      .value("axial_c", BallbarTest::axial_c)
      .value("tangential_tilt", BallbarTest::tangential_tilt)
      .value("tangential_c", BallbarTest::tangential_c);
  pyb::enum_<SweepDirection>(m, "SweepDirection", "ccw: towards increasing angles; cw: back.")
      .value("ccw", SweepDirection::ccw)
      .value("cw", SweepDirection::cw);
  pyb::enum_<RadialSide>(m, "RadialSide", "Flynn's +-L0 of the radial C test.")
      .value("outside", RadialSide::outside)
      .value("inside", RadialSide::inside);
  pyb::enum_<SegmentKind>(m, "SegmentKind")
      .value("test", SegmentKind::test)
      .value("rotary_transition", SegmentKind::rotary_transition)
      .value("arc_transition", SegmentKind::arc_transition);
  pyb::enum_<NcDialect>(m, "NcDialect")
      .value("linuxcnc", NcDialect::linuxcnc)
      .value("heidenhain", NcDialect::heidenhain)
      .value("siemens", NcDialect::siemens)
      .value("fanuc", NcDialect::fanuc);

  m.def("test_label", &test_label, pyb::arg("test"), pyb::arg("machine"),
        "Session label of a test on a machine, e.g. 'radial_A'.");
  m.def("parse_ballbar_test", &parse_ballbar_test, pyb::arg("label"), pyb::arg("machine"),
        "Test from its session label ('radial_B' only on a BC-trt machine).");
  m.def("default_ballbar_tests", &default_ballbar_tests,
        "sphere_xy, sphere_yz, sphere_zx, radial tilt, axial C, radial C, axial tilt.");
  m.def("parse_radial_side", &parse_radial_side, pyb::arg("text"));
  m.def("parse_sweep_direction", &parse_sweep_direction, pyb::arg("text"));
  m.def("is_rotary_test", &is_rotary_test, pyb::arg("test"));
  m.def("run_label", &run_label, pyb::arg("test"), pyb::arg("direction"), pyb::arg("feed_factor"),
        pyb::arg("setup"), "Label of one run: test label, '_cw', '_f<feed>'.");
  m.def("parse_nc_dialect", &parse_nc_dialect, pyb::arg("text"));
}

// The set-up of the single set-up test.
void bind_ballbar_setup(pyb::module_& m) {
  const BallbarSetup d;
  pyb::class_<BallbarSetup>(m, "BallbarSetup",
                            "Layout of the single set-up ballbar test (mm, deg, mm/min, deg/min).")
      .def(
          pyb::init([](MachineType machine, double ballbar_length, const Eigen::Vector3d& pivot,
                       std::optional<std::array<double, 2>> tilt_range_deg,
                       std::array<double, 2> rot_range_deg, double step_deg, double feed_mm_per_min,
                       double feed_deg_per_min, std::vector<BallbarTest> tests,
                       RadialSide radial_c_side, std::optional<double> axial_c_tilt_deg,
                       std::vector<SweepDirection> directions, std::vector<double> feed_factors) {
            BallbarSetup s;
            s.machine = machine;
            s.ballbar_length = ballbar_length;
            s.pivot = pivot;
            s.tilt_range_deg = tilt_range_deg.value_or(default_tilt_range_deg(machine));
            s.rot_range_deg = rot_range_deg;
            s.step_deg = step_deg;
            s.feed_mm_per_min = feed_mm_per_min;
            s.feed_deg_per_min = feed_deg_per_min;
            s.tests = std::move(tests);
            s.radial_c_side = radial_c_side;
            s.axial_c_tilt_deg = axial_c_tilt_deg;
            s.directions = std::move(directions);
            s.feed_factors = std::move(feed_factors);
            return s;
          }),
          pyb::arg("machine") = d.machine, pyb::arg("ballbar_length") = d.ballbar_length,
          pyb::arg("pivot") = d.pivot, pyb::arg("tilt_range_deg") = pyb::none(),
          pyb::arg("rot_range_deg") = d.rot_range_deg, pyb::arg("step_deg") = d.step_deg,
          pyb::arg("feed_mm_per_min") = d.feed_mm_per_min,
          pyb::arg("feed_deg_per_min") = d.feed_deg_per_min, pyb::arg("tests") = d.tests,
          pyb::arg("radial_c_side") = d.radial_c_side, pyb::arg("axial_c_tilt_deg") = pyb::none(),
          pyb::arg("directions") = d.directions, pyb::arg("feed_factors") = d.feed_factors,
          "tilt_range_deg None: default_tilt_range_deg(machine); axial_c_tilt_deg None: "
          "default_axial_c_tilt_deg(machine).")
      .def_readwrite("machine", &BallbarSetup::machine)
      .def_readwrite("ballbar_length", &BallbarSetup::ballbar_length, "L0, mm")
      .def_readwrite("pivot", &BallbarSetup::pivot, "nominal pivot ball centre, table frame, mm")
      .def_readwrite("tilt_range_deg", &BallbarSetup::tilt_range_deg)
      .def_readwrite("rot_range_deg", &BallbarSetup::rot_range_deg,
                     "C sweep, deg; a 360 deg span is a full turn without its repeated end")
      .def_readwrite("step_deg", &BallbarSetup::step_deg)
      .def_readwrite("feed_mm_per_min", &BallbarSetup::feed_mm_per_min)
      .def_readwrite("feed_deg_per_min", &BallbarSetup::feed_deg_per_min)
      .def_readwrite("tests", &BallbarSetup::tests)
      .def_readwrite("radial_c_side", &BallbarSetup::radial_c_side)
      .def_readwrite("directions", &BallbarSetup::directions,
                     "directions of every rotary test, in order")
      .def_readwrite("feed_factors", &BallbarSetup::feed_factors,
                     "feeds of every rotary test as factors of the set-up's feeds; the first is 1")
      .def_readwrite("axial_c_tilt_deg", &BallbarSetup::axial_c_tilt_deg,
                     "tilt held during axial_c, deg; None: default_axial_c_tilt_deg(machine)");
  m.def("default_tilt_range_deg", &default_tilt_range_deg, pyb::arg("machine"));
  m.def("default_axial_c_tilt_deg", &default_axial_c_tilt_deg, pyb::arg("machine"));
}

// The planned toolpath and the planner.
void bind_ballbar_toolpath(pyb::module_& m) {
  pyb::class_<TransitionArc>(m, "TransitionArc",
                             "Great-circle arc about the pivot at rotary zero (mm, rad).")
      .def_readonly("start", &TransitionArc::start)
      .def_readonly("end", &TransitionArc::end)
      .def_readonly("center", &TransitionArc::center)
      .def_readonly("axis", &TransitionArc::axis)
      .def_readonly("angle", &TransitionArc::angle)
      .def_readonly("principal_axis", &TransitionArc::principal_axis);

  pyb::class_<PlanSegment>(m, "PlanSegment")
      .def_readonly("label", &PlanSegment::label)
      .def_readonly("kind", &PlanSegment::kind)
      .def_readonly("test", &PlanSegment::test)
      .def_readonly("direction", &PlanSegment::direction)
      .def_readonly("feed_factor", &PlanSegment::feed_factor)
      .def_readonly("arc", &PlanSegment::arc)
      .def_property_readonly("num_samples", [](const PlanSegment& s) { return s.samples.size(); });

  pyb::class_<BallbarPlan>(m, "BallbarPlan",
                           "Planned toolpath; per-sample arrays in program order.")
      .def_readonly("setup", &BallbarPlan::setup)
      .def_property_readonly(
          "compensation",
          [](const BallbarPlan& p) -> std::optional<Eigen::Matrix<double, 8, 1>> {
            if (!p.compensation) return std::nullopt;
            return p.compensation->v;
          },
          "(8,) location errors the machine axes were computed with, or None (nominal)")
      .def_readonly("segments", &BallbarPlan::segments)
      .def_property_readonly("num_samples", &BallbarPlan::num_samples)
      .def_property_readonly("duration", &BallbarPlan::duration, "s")
      .def_property_readonly(
          "labels", [](const BallbarPlan& p) { return tabulate(p).labels; },
          "segment label per sample ('transition' between tests)")
      .def_property_readonly("segment_index",
                             [](const BallbarPlan& p) { return tabulate(p).segment; })
      .def_property_readonly(
          "time", [](const BallbarPlan& p) { return tabulate(p).time; }, "(N,) s")
      .def_property_readonly(
          "p_table", [](const BallbarPlan& p) { return tabulate(p).p_table; },
          "(N, 3) tool-cup ball centre, table frame, mm")
      .def_property_readonly(
          "angles_deg", [](const BallbarPlan& p) { return tabulate(p).angles_deg; },
          "(N, 2) tilt (A or B) and C, deg")
      .def_property_readonly(
          "machine_axes", [](const BallbarPlan& p) { return tabulate(p).machine_axes; },
          "(N, 5) X, Y, Z (mm), tilt, C (deg)")
      .def("commanded_session", &commanded_session,
           "The test samples as a BallbarSession (length = L0), e.g. for simulate_ballbar.");

  m.def(
      "plan_ballbar_test",
      [](const BallbarSetup& setup,
         const std::optional<pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>>&
             identified) {
        std::optional<LocationErrors<double>> e;
        if (identified) e = LocationErrors<double>(vec_of<8>(*identified, "identified"));
        pyb::gil_scoped_release release;
        return plan_ballbar_test(setup, e);
      },
      pyb::arg("setup") = BallbarSetup{}, pyb::arg("identified") = pyb::none(),
      R"doc(Plan the single set-up ballbar test (Flynn et al. 2016, Sec. 3).

Parameters
----------
setup : BallbarSetup
identified : (8,) location errors (mm, rad; order of location_error_names), optional.
    Given, the machine axes are the compensated command for that machine.

Returns
-------
BallbarPlan: labels, time (N,), p_table (N, 3), angles_deg (N, 2), machine_axes (N, 5))doc");
}

// NC program options and writer.
void bind_nc_program(pyb::module_& m) {
  const NcProgramOptions o;
  pyb::class_<NcProgramOptions>(m, "NcProgramOptions")
      .def(pyb::init([](int decimals, int tool, bool stop_to_mount, std::string program_name,
                        int program_number) {
             return NcProgramOptions{decimals, tool, stop_to_mount, std::move(program_name),
                                     program_number};
           }),
           pyb::arg("decimals") = o.decimals, pyb::arg("tool") = o.tool,
           pyb::arg("stop_to_mount") = o.stop_to_mount, pyb::arg("program_name") = o.program_name,
           pyb::arg("program_number") = o.program_number)
      .def_readwrite("decimals", &NcProgramOptions::decimals)
      .def_readwrite("tool", &NcProgramOptions::tool)
      .def_readwrite("stop_to_mount", &NcProgramOptions::stop_to_mount)
      .def_readwrite("program_name", &NcProgramOptions::program_name)
      .def_readwrite("program_number", &NcProgramOptions::program_number);

  m.def("write_nc_program", &write_nc_program, pyb::arg("plan"), pyb::arg("dialect"),
        pyb::arg("options") = NcProgramOptions{},
        "NC program text: 'linuxcnc' machine axes (G93 G1), or TCP programs for 'heidenhain' "
        "(FUNCTION TCPM), 'siemens' (TRAORI), 'fanuc' (G43.4).");
  m.def(
      "write_nc_program",
      [](const BallbarPlan& plan, const std::string& dialect, const NcProgramOptions& options) {
        return write_nc_program(plan, parse_nc_dialect(dialect), options);
      },
      pyb::arg("plan"), pyb::arg("dialect"), pyb::arg("options") = NcProgramOptions{});
}

// Runs of the measure -> compensate -> measure-again experiment (ballbar/chain_runs.hpp).
void bind_chain_runs(pyb::module_& m) {
  m.def(
      "record_run",
      [](const BallbarSession& nominal, const BallbarSession& program,
         const BallbarMachineModel& machine, std::optional<std::uint64_t> seed,
         const std::string& method, double noise_um, double noise_rho) {
        return record_run(nominal, program, machine, seed, {method, noise_um, noise_rho});
      },
      pyb::arg("nominal"), pyb::arg("program"), pyb::arg("machine"), pyb::arg("seed") = pyb::none(),
      pyb::arg("method") = "paper", pyb::arg("noise_um") = 0.5, pyb::arg("noise_rho") = 0.0,
      "The session a run records: `program` played on `machine`, AR(1) noise (seed; none if None), "
      "recorded against the `nominal` program's X,Y,Z and pivot.");
  m.def(
      "identify_runs",
      [](const BallbarSetup& setup, const std::vector<BallbarMachineModel>& machines,
         const std::optional<Array>& compensate_for, const std::vector<std::uint64_t>& seeds,
         const std::string& method, double noise_um, double noise_rho) {
        const LocationErrorRows c =
            compensate_for ? rows_of<8>(*compensate_for, "compensate_for") : LocationErrorRows();
        pyb::gil_scoped_release release;
        return identify_runs(setup, machines, c, seeds, {method, noise_um, noise_rho});
      },
      pyb::arg("setup"), pyb::arg("machines"), pyb::arg("compensate_for") = pyb::none(),
      pyb::arg("seeds") = std::vector<std::uint64_t>{}, pyb::arg("method") = "paper",
      pyb::arg("noise_um") = 0.5, pyb::arg("noise_rho") = 0.0,
      R"doc(Location errors identified from one run on each machine (Flynn et al. 2016, Sec. 4).

Parameters
----------
setup : BallbarSetup of the planned test
machines : [BallbarMachineModel], one run each
compensate_for : (N, 8) location errors the test of run i is compensated for (None: nominal)
seeds : one AR(1) noise seed per run ([]: noise-free)
method : identification, "paper" or "joint"
noise_um, noise_rho : reading noise, um, and its AR(1) correlation

Returns
-------
(N, 8) identified location errors, mm and rad, in location_error_names order)doc");
}

}  // namespace

void bind_ballbar_plan(pyb::module_& m) {
  bind_ballbar_tests(m);
  bind_ballbar_setup(m);
  bind_ballbar_toolpath(m);
  bind_nc_program(m);
  bind_chain_runs(m);
}

}  // namespace rotacal::py
