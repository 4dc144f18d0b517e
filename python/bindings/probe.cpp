// SPDX-License-Identifier: BSD-3-Clause
// Bindings for the touch probe (include/rotacal/probe, io/probe_file.hpp): session, reader and
// writer, simulation, the joint fit and the cycles' method, the probing program and its log.
// Thin: numpy in and out.
#include <pybind11/stl.h>

#include <optional>
#include <tuple>

#include "json_value.hpp"
#include "numpy.hpp"
#include "rotacal/diagnose/probe_diagnosis.hpp"
#include "rotacal/diagnose/uncertainty_budget.hpp"
#include "rotacal/io/probe_file.hpp"
#include "rotacal/probe/identify.hpp"
#include "rotacal/probe/model_document.hpp"
#include "rotacal/probe/monte_carlo.hpp"
#include "rotacal/probe/nc_program.hpp"
#include "rotacal/probe/simulate.hpp"
#include "rotacal/probe/touch_model.hpp"

namespace rotacal::py {

namespace {
template <typename F>
Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> columns(
    const ProbeSession& s, int k, F f) {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(
      static_cast<Eigen::Index>(s.samples.size()), k);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) = f(s.samples[i]);
  return m;
}

std::vector<RotaryAngles<double>> angles_of(const Array& a) {
  const auto m = rows_of<2>(a, "poses_deg");
  std::vector<RotaryAngles<double>> out;
  for (Eigen::Index i = 0; i < m.rows(); ++i) out.push_back({m(i, 0), m(i, 1)});
  return out;
}

// The session, its reader and writer, and the probe's catalogue entries.
void bind_probe_session(pyb::module_& m) {
  pyb::class_<ProbeSession>(m, "ProbeSession",
                            "A rotacal-probe/1 touch-probe session (mm, deg, s).")
      .def_readonly("machine", &ProbeSession::machine)
      .def_property_readonly(
          "sphere", [](const ProbeSession& s) { return Eigen::Vector3d(s.sphere); },
          "nominal sphere centre, table frame, mm")
      .def_readonly("sphere_diameter", &ProbeSession::sphere_diameter)
      .def_readonly("stylus_diameter", &ProbeSession::stylus_diameter)
      .def_property_readonly("trigger_radius", &ProbeSession::trigger_radius)
      .def_readonly("noise_um", &ProbeSession::noise_um)
      .def_readonly("warnings", &ProbeSession::warnings,
                    "what the reader found suspicious but kept")
      .def_property_readonly(
          "poses",
          [](const ProbeSession& s) {
            std::vector<std::string> out;
            for (const ProbeSample& x : s.samples) out.push_back(x.pose);
            return out;
          },
          "pose label of every touch")
      .def_property_readonly("pose_names", &ProbeSession::poses, "distinct pose labels, in order")
      .def_property_readonly("time",
                             [](const ProbeSession& s) {
                               Eigen::VectorXd t(static_cast<Eigen::Index>(s.samples.size()));
                               for (std::size_t i = 0; i < s.samples.size(); ++i)
                                 t[static_cast<Eigen::Index>(i)] = s.samples[i].time;
                               return t;
                             })
      .def_property_readonly(
          "xyz",
          [](const ProbeSession& s) {
            return columns(s, 3, [](const ProbeSample& x) { return x.xyz.transpose(); });
          },
          "latched X, Y, Z (N, 3), mm")
      .def_property_readonly(
          "angles_deg",
          [](const ProbeSession& s) {
            return columns(s, 2, [](const ProbeSample& x) {
              return Eigen::RowVector2d(x.tilt_deg, x.rot_deg);
            });
          },
          "tilt and rotary angle of every touch (N, 2), deg")
      .def_property_readonly(
          "n",
          [](const ProbeSession& s) {
            return columns(s, 3, [](const ProbeSample& x) { return x.n.transpose(); });
          },
          "unit approach directions (N, 3), machine frame")
      .def("__len__", [](const ProbeSession& s) { return s.samples.size(); })
      .def("__repr__", [](const ProbeSession& s) {
        return "<ProbeSession " + to_string(s.machine) + ", " + std::to_string(s.samples.size()) +
               " touches at " + std::to_string(s.poses().size()) + " poses>";
      });
  m.def("read_probe", &read_probe, pyb::arg("path"),
        "Read a rotacal-probe/1 file (io/probe_file.hpp).");
  m.def("write_probe", &write_probe, pyb::arg("session"), pyb::arg("path"));
  m.def("format_probe", &format_probe, pyb::arg("session"));
  m.def("read_instrument_session", &read_instrument_session, pyb::arg("path"),
        "Read a ballbar, R-test or touch-probe session (chosen by its format line).");
  m.def("probe_effect_catalogue", &probe_effect_catalogue, pyb::arg("machine"),
        pyb::arg("max_harmonic") = 4,
        "The catalogue entries of a probe session: effect_catalogue and stylus_radius_offset, "
        "probe_lobing.");
}

// The joint fit, the cycles' method, the diagnosis and its uncertainty budget.
void bind_probe_identification(pyb::module_& m) {
  pyb::class_<ProbeIdentification, Identification>(m, "ProbeIdentification")
      .def_property_readonly("machine",
                             [](const ProbeIdentification& r) { return r.model.machine; })
      .def_property_readonly(
          "errors", [](const ProbeIdentification& r) { return Eigen::VectorXd(r.model.errors.v); })
      .def_property_readonly("effects",
                             [](const ProbeIdentification& r) { return ids_of(r.model.effects); })
      .def_property_readonly("effect_params",
                             [](const ProbeIdentification& r) { return r.model.effect_params; })
      .def_property_readonly("sphere",
                             [](const ProbeIdentification& r) { return Eigen::Vector3d(r.sphere); })
      .def_property_readonly("pose_centres",
                             [](const ProbeIdentification& r) { return rows_from(r.pose_centres); })
      .def_readonly("pose_labels", &ProbeIdentification::pose_labels)
      .def_readonly("dispersion_um", &ProbeIdentification::dispersion_um);

  m.def(
      "identify_probe",
      [](const ProbeSession& session, const std::vector<std::string>& effects,
         const std::string& noise) {
        ProbeFitOptions o;
        o.effects = effects_of(effects);
        o.noise.noise = noise_handling_from_string(noise);
        pyb::gil_scoped_release release;
        return identify_probe(session, o);
      },
      pyb::arg("session"), pyb::arg("effects") = std::vector<std::string>{},
      pyb::arg("noise") = "auto",
      "Joint fit of every touch: location errors, the sphere's table position (and effects), with "
      "observability and the noise model (probe/identify.hpp); noise 'auto' or 'white'.");
  m.def(
      "identify_probe_cycles",
      [](const ProbeSession& session, bool radius_known) {
        pyb::gil_scoped_release release;
        return identify_probe_cycles(session, ProbeCyclesOptions{radius_known});
      },
      pyb::arg("session"), pyb::arg("radius_known") = true,
      "The controller cycles' method: sphere per pose, plane and circle of the centres per table "
      "axis.");
  pyb::class_<ProbeMonteCarlo>(m, "ProbeMonteCarlo")
      .def_readonly("draws", &ProbeMonteCarlo::draws)
      .def_readonly("noise_um", &ProbeMonteCarlo::noise_um)
      .def_readonly("noise", &ProbeMonteCarlo::noise)
      .def_readonly("parameters", &ProbeMonteCarlo::parameters)
      .def_readonly("values", &ProbeMonteCarlo::values);
  m.def(
      "monte_carlo_probe",
      [](const ProbeSession& session, const ProbeIdentification& result, int draws,
         std::uint64_t seed, const std::string& noise, const pyb::object& progress) {
        ProbeMonteCarloOptions o;
        o.draws = draws;
        o.seed = seed;
        o.noise = noise_handling_from_string(noise);
        o.progress = progress_callback(progress);
        pyb::gil_scoped_release release;
        return monte_carlo_probe(session, result, o);
      },
      pyb::arg("session"), pyb::arg("result"), pyb::arg("draws") = 100, pyb::arg("seed") = 1,
      pyb::arg("noise") = "auto", pyb::arg("progress") = pyb::none(),
      "Monte Carlo check of a touch-probe joint fit's 1-sigma (probe/monte_carlo.hpp): draw k "
      "(seed + k) moves "
      "every touch along its direction to the identified machine plus the fit's noise, refitted "
      "with `noise` "
      "('auto' or 'white', as the fit was); progress: optional callable(done, total).");
  m.def(
      "probe_model_document",
      [](const ProbeIdentification& identification, const std::string& session_name) {
        return from_json(probe_model_document(identification, session_name));
      },
      pyb::arg("identification"), pyb::arg("session_name"),
      "The rotacal-model/1 document (kind probe) of a joint touch-probe fit "
      "(rotacal/probe/model_document.hpp).");

  m.def(
      "diagnose_probe",
      [](const ProbeSession& session, const DiagnosisOptions& options) {
        pyb::gil_scoped_release release;
        return diagnose_probe(session, options);
      },
      pyb::arg("session"), pyb::arg("options") = DiagnosisOptions{},
      "Diagnose a touch-probe session (diagnose/probe_diagnosis.hpp): catalogue effects and the "
      "probe's "
      "stylus_radius_offset and probe_lobing over the joint fit's baseline.");
  m.def(
      "uncertainty_budget_probe",
      [](const ProbeSession& session, const Diagnosis& diagnosis, const PlausibleSizes& sizes,
         double coverage) {
        pyb::gil_scoped_release release;
        return uncertainty_budget(ProbeDiagnosisProblem(session), diagnosis, sizes, coverage);
      },
      pyb::arg("session"), pyb::arg("diagnosis"), pyb::arg("sizes") = PlausibleSizes{},
      pyb::arg("coverage") = 0.95,
      "GUM budget of the location errors of diagnose_probe's result (the probe's entries: stylus "
      "calibration, "
      "lobing).");
}

// The probing program, its log, the default pattern and the simulation.
void bind_probe_program(pyb::module_& m) {
  m.def(
      "write_probe_nc_program",
      [](MachineType machine, const std::string& dialect, std::optional<Array> poses_deg,
         const Array& sphere, double sphere_diameter, double stylus_diameter,
         const std::string& log_file, int tool, int decimals, double approach_mm, double probe_feed,
         double positioning_feed, const std::vector<Array>& pose_directions,
         std::optional<std::tuple<std::string, double, double, double, double, double>> thermal) {
        ProbePattern p = default_probe_pattern(machine);
        if (poses_deg) p.poses_deg = angles_of(*poses_deg);
        for (const Array& d : pose_directions)
          p.pose_directions.push_back(vectors_of(d, "pose_directions"));
        p.sphere = vec_of<3>(sphere, "sphere");
        p.sphere_diameter = sphere_diameter;
        p.stylus_diameter = stylus_diameter;
        ProbeProgramOptions o;
        o.log_file = log_file;
        o.tool = tool;
        o.decimals = decimals;
        o.approach_mm = approach_mm;
        o.probe_feed_mm_per_min = probe_feed;
        o.feed_mm_per_min = positioning_feed;
        if (thermal) {
          const auto& [axis, speed, heat, cool, interval, max_speed] = *thermal;
          if (axis.size() != 1) throw InvalidArgument("thermal: axis '" + axis + "'");
          o.thermal = ThermalProgramDuty{axis[0], speed, heat, cool, interval, max_speed};
        }
        return write_probe_nc_program(machine, p, parse_nc_dialect(dialect), o);
      },
      pyb::arg("machine"), pyb::arg("dialect"), pyb::arg("poses_deg") = pyb::none(),
      pyb::arg("sphere") = Eigen::Vector3d(150.0, 0.0, 80.0).eval(),
      pyb::arg("sphere_diameter") = 25.0, pyb::arg("stylus_diameter") = 6.0,
      pyb::arg("log_file") = ProbeProgramOptions().log_file, pyb::arg("tool") = 1,
      pyb::arg("decimals") = 4, pyb::arg("approach_mm") = ProbeProgramOptions().approach_mm,
      pyb::arg("probe_feed") = ProbeProgramOptions().probe_feed_mm_per_min,
      pyb::arg("positioning_feed") = ProbeProgramOptions().feed_mm_per_min,
      pyb::arg("pose_directions") = std::vector<Array>{}, pyb::arg("thermal") = pyb::none(),
      "The probing program of the default pattern's directions (or each pose's `pose_directions`, "
      "(K_i, 3)) "
      "at `poses_deg` (default: its poses) "
      "(probe/nc_program.hpp); linuxcnc only. approach_mm: the G38.2 starts this far outside the "
      "trigger "
      "sphere; probe_feed: its feed, positioning_feed: the G1 moves' to and from its start, "
      "mm/min. thermal: (axis, speed rev/min, heat s, cool s, interval s, max speed rev/min), the "
      "pattern as one epoch per interval and the duty between (ThermalProgramDuty).");
  m.def("read_linuxcnc_probe_log", &read_linuxcnc_probe_log, pyb::arg("path"), pyb::arg("plan"),
        pyb::arg("max_off_line_mm") = 1.0,
        "The session of a LinuxCNC probing log: its latched X Y Z in the plan's rows "
        "(probe/nc_program.hpp); a latch farther than max_off_line_mm from its commanded line is "
        "refused.");
  m.def(
      "default_probe_poses_deg",
      [](MachineType machine) {
        const ProbePattern p = default_probe_pattern(machine);
        Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> a(
            static_cast<Eigen::Index>(p.poses_deg.size()), 2);
        for (std::size_t i = 0; i < p.poses_deg.size(); ++i)
          a.row(static_cast<Eigen::Index>(i)) << p.poses_deg[i].tilt, p.poses_deg[i].rot;
        return std::make_pair(a, rows_from(p.directions));
      },
      pyb::arg("machine"),
      "(poses (P, 2) tilt and rotary deg, directions (K, 3)) of default_probe_pattern.");
  m.def(
      "simulate_probe",
      [](MachineType machine, const Array& errors, const std::vector<std::string>& effects,
         const std::vector<double>& effect_params, const Array& sphere_offset, double noise_um,
         double ar1_rho, std::uint64_t seed, std::optional<Array> poses_deg,
         std::optional<Array> directions, const Array& sphere, double sphere_diameter,
         double stylus_diameter, const std::vector<Array>& pose_directions) {
        MachineModel t;
        t.machine = machine;
        t.errors = LocationErrors<double>(vec_of<8>(errors, "errors"));
        t.effects = effects_of(effects);
        t.effect_params = effect_params;
        ProbeSimOptions o;
        o.pattern = default_probe_pattern(machine);
        if (poses_deg) o.pattern.poses_deg = angles_of(*poses_deg);
        if (directions) o.pattern.directions = vectors_of(*directions, "directions");
        for (const Array& d : pose_directions)
          o.pattern.pose_directions.push_back(vectors_of(d, "pose_directions"));
        o.pattern.sphere = vec_of<3>(sphere, "sphere");
        o.pattern.sphere_diameter = sphere_diameter;
        o.pattern.stylus_diameter = stylus_diameter;
        o.sphere_offset = vec_of<3>(sphere_offset, "sphere_offset");
        o.noise_um = noise_um;
        o.ar1_rho = ar1_rho;
        o.seed = seed;
        pyb::gil_scoped_release release;
        const ProbeSimulation sim = simulate_probe(t, o);
        return std::make_pair(sim.session, Eigen::Vector3d(sim.sphere_actual));
      },
      pyb::arg("machine"), pyb::arg("errors"), pyb::arg("effects") = std::vector<std::string>{},
      pyb::arg("effect_params") = std::vector<double>{},
      pyb::arg("sphere_offset") = Eigen::Vector3d::Zero().eval(), pyb::arg("noise_um") = 0.5,
      pyb::arg("ar1_rho") = 0.0, pyb::arg("seed") = 1, pyb::arg("poses_deg") = pyb::none(),
      pyb::arg("directions") = pyb::none(),
      pyb::arg("sphere") = Eigen::Vector3d(150.0, 0.0, 80.0).eval(),
      pyb::arg("sphere_diameter") = 25.0, pyb::arg("stylus_diameter") = 6.0,
      pyb::arg("pose_directions") = std::vector<Array>{},
      "Simulate a touch-probe session (probe/simulate.hpp): (session, actual sphere centre). Poses "
      "default "
      "to default_probe_pattern's.");
}

}  // namespace

void bind_probe(pyb::module_& m) {
  bind_probe_session(m);
  bind_probe_identification(m);
  bind_probe_program(m);
}

}  // namespace rotacal::py
