// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/hw: virtual instruments, recorders, serial ports. Thin: the
// recorders run in C++ with the GIL released; the progress callback takes it back.
#ifdef ROTACAL_WITH_HW  // the module is built without the serial layer when libserialport is off
#include <pybind11/functional.h>

#include "numpy.hpp"
#include "rotacal/hw/recorder.hpp"
#include "rotacal/hw/virtual_instrument.hpp"

// In a namespace of its own: the extension compiles the binding files as one unity file
// (python/CMakeLists.txt), and the using-directive must not reach the files after this one.
namespace rotacal::py::hw_bindings {

using namespace rotacal::hw;

namespace {

pyb::dict stats_dict(const VirtualStats& s) {
  pyb::dict d;
  d["frames_sent"] = s.frames_sent;
  d["frames_dropped"] = s.frames_dropped;
  d["frames_corrupted"] = s.frames_corrupted;
  d["replies_sent"] = s.replies_sent;
  d["finished"] = s.finished;
  return d;
}

SerialSettings settings_of(int baud) {
  SerialSettings s;
  s.baud = baud;
  return s;
}

// Options of both recorders; the Python callable (if any) is called with the GIL held.
RecordOptions record_options(double rate_hz, double speed, double silence_timeout_s, bool zero,
                             const std::optional<pyb::function>& progress) {
  RecordOptions o;
  o.rate_hz = rate_hz;
  o.speed = speed;
  o.silence_timeout_s = silence_timeout_s;
  o.zero = zero;
  if (progress) {
    o.progress = [fn = *progress](const RecordProgress& p) {
      pyb::gil_scoped_acquire gil;
      return fn(p.rows, p.lost, p.corrupt, p.device_time_s, p.program_duration_s).cast<bool>();
    };
  }
  return o;
}

// What every virtual instrument offers: its port, start, stop, finished, stats.
template <typename Instrument>
void instrument_methods(pyb::class_<Instrument>& c) {
  c.def_property_readonly("port", &Instrument::port)
      .def("start", &Instrument::start)
      .def("stop", &Instrument::stop, pyb::call_guard<pyb::gil_scoped_release>())
      .def_property_readonly("finished", &Instrument::finished)
      .def("stats", [](const Instrument& v) { return stats_dict(v.stats()); });
}

// A ballbar recording of `plan` (a BallbarPlan or a CircularPlanResult, played as Program) from
// a serial port, the GIL released while it reads.
template <typename Program, typename Plan>
RecordSummary record_plan(const std::string& port, const Plan& plan, const std::string& path,
                          int baud, double rate_hz, bool zero, double silence_timeout_s,
                          const std::optional<pyb::function>& progress) {
  const RecordOptions o = record_options(rate_hz, 1.0, silence_timeout_s, zero, progress);
  pyb::gil_scoped_release release;
  auto transport = open_port(port, settings_of(baud));
  return record_ballbar(*transport, Program(plan), path, o);
}

}  // namespace

void bind(pyb::module_& m) {
  pyb::class_<FaultInjection>(m, "FaultInjection",
                              "Faults a virtual instrument acts out (counted in frames).")
      .def(pyb::init<>())
      .def_readwrite("garbage_every", &FaultInjection::garbage_every)
      .def_readwrite("corrupt_every", &FaultInjection::corrupt_every)
      .def_readwrite("drop_every", &FaultInjection::drop_every)
      .def_readwrite("split_frames", &FaultInjection::split_frames)
      .def_readwrite("close_after", &FaultInjection::close_after)
      .def_readwrite("silence_after", &FaultInjection::silence_after);

  pyb::class_<VirtualBallbar> ballbar(
      m, "VirtualBallbar", "A ballbar on a simulated machine, served on a pseudo-terminal.");
  ballbar.def(pyb::init([](const BallbarPlan& plan, const BallbarMachineModel& truth,
                           double noise_um, std::uint64_t seed, double rate_hz, double speed,
                           int baud, const FaultInjection& faults) {
                VirtualBallbarOptions o;
                o.truth = truth;
                o.noise_um = noise_um;
                o.seed = seed;
                o.rate_hz = rate_hz;
                o.speed = speed;
                o.baud = baud;
                o.faults = faults;
                return std::make_unique<VirtualBallbar>(ProgramTimeline(plan), o);
              }),
              pyb::arg("plan"), pyb::arg("truth"), pyb::arg("noise_um") = 0.5, pyb::arg("seed") = 1,
              pyb::arg("rate_hz") = 1000.0, pyb::arg("speed") = 1.0, pyb::arg("baud") = 115200,
              pyb::arg("faults") = FaultInjection{});
  instrument_methods(ballbar);

  pyb::class_<VirtualCircularBallbar> circular(
      m, "VirtualCircularBallbar",
      "A ballbar on a machine running an ISO 230-4 circular program (circular/timeline.hpp), "
      "served on a pseudo-terminal; the machine and noise as simulate_circular's options.");
  circular.def(pyb::init([](const CircularPlanResult& plan, const CircularSimulationOptions& sim,
                            double rate_hz, double speed, int baud, const FaultInjection& faults) {
                 return std::make_unique<VirtualCircularBallbar>(
                     CircularTimeline(plan),
                     VirtualCircularBallbarOptions{sim, rate_hz, speed, baud, faults});
               }),
               pyb::arg("plan"), pyb::arg("options"), pyb::arg("rate_hz") = 250.0,
               pyb::arg("speed") = 1.0, pyb::arg("baud") = 115200,
               pyb::arg("faults") = FaultInjection{});
  instrument_methods(circular);

  pyb::class_<VirtualRtest> rtest(
      m, "VirtualRtest", "An R-test on a simulated B/C table, served on a pseudo-terminal.");
  instrument_methods(rtest);
  rtest
      .def(pyb::init([](MachineType machine, const Array& errors,
                        const std::vector<std::string>& effects,
                        const std::vector<double>& effect_params, const std::vector<double>& b_deg,
                        const std::vector<double>& c_deg, const Array& nests, double dwell_s,
                        double noise_um, double probe_zero_um, const Array& probe_dirs,
                        unsigned seed, const std::string& mode, double rate_hz, double speed,
                        int baud, const FaultInjection& faults) {
             VirtualRtestOptions o;
             o.truth.machine = machine;
             o.truth.errors = LocationErrors<double>(vec_of<8>(errors, "errors"));
             o.truth.effects = effects_of(effects);
             o.truth.effect_params = effect_params;
             o.sim.pattern.b_deg = b_deg;
             o.sim.pattern.c_deg = c_deg;
             o.sim.pattern.nests = vectors_of(nests, "nests");
             o.sim.pattern.dwell_s = dwell_s;
             o.sim.noise_um = noise_um;
             o.sim.probe_zero_um = probe_zero_um;
             o.sim.seed = seed;
             o.probe_dirs = matrix3_of(probe_dirs, "probe_dirs");
             o.mode = parse_probe_mode(mode);
             o.rate_hz = rate_hz;
             o.speed = speed;
             o.baud = baud;
             o.faults = faults;
             return std::make_unique<VirtualRtest>(o);
           }),
           pyb::arg("machine"), pyb::arg("errors"), pyb::arg("effects"), pyb::arg("effect_params"),
           pyb::arg("b_deg"), pyb::arg("c_deg"), pyb::arg("nests"), pyb::arg("dwell_s"),
           pyb::arg("noise_um"), pyb::arg("probe_zero_um"), pyb::arg("probe_dirs"),
           pyb::arg("seed"), pyb::arg("mode") = "keyence", pyb::arg("rate_hz") = 100.0,
           pyb::arg("speed") = 1.0, pyb::arg("baud") = 115200,
           pyb::arg("faults") = FaultInjection{})
      .def_property_readonly("program", &VirtualRtest::program,
                             "Commanded rows (set-up, time, B, C, X, Y, Z) and nests.")
      .def_property_readonly("probe_zeros",
                             [](const VirtualRtest& v) { return rows_from(v.probe_zeros()); });

  pyb::class_<RecordSummary>(m, "RecordSummary")
      .def_readonly("rows", &RecordSummary::rows)
      .def_readonly("frames", &RecordSummary::frames)
      .def_readonly("lost", &RecordSummary::lost)
      .def_readonly("crc_errors", &RecordSummary::crc_errors)
      .def_readonly("malformed", &RecordSummary::malformed)
      .def_readonly("garbage_bytes", &RecordSummary::garbage_bytes)
      .def_readonly("over_range", &RecordSummary::over_range)
      .def_readonly("timeouts", &RecordSummary::timeouts)
      .def_readonly("outside_window", &RecordSummary::outside_window)
      .def_property_readonly("reason", [](const RecordSummary& s) { return to_string(s.reason); })
      .def_readonly("detail", &RecordSummary::detail)
      .def("describe", &RecordSummary::describe);

  m.def("record_ballbar", &record_plan<ProgramTimeline, BallbarPlan>, pyb::arg("port"),
        pyb::arg("plan"), pyb::arg("path"), pyb::arg("baud") = 115200, pyb::arg("rate_hz") = 1000.0,
        pyb::arg("zero") = false, pyb::arg("silence_timeout_s") = 3.0,
        pyb::arg("progress") = std::nullopt,
        "Record a ballbar test from a serial port into a rotacal-ballbar/1 file (hw/recorder.hpp). "
        "progress(rows, lost, corrupt, t_s, duration_s) -> bool is called a few times a second; "
        "returning False stops the recording.");
  m.def("record_circular_ballbar", &record_plan<CircularTimeline, CircularPlanResult>,
        pyb::arg("port"), pyb::arg("plan"), pyb::arg("path"), pyb::arg("baud") = 115200,
        pyb::arg("rate_hz") = 250.0, pyb::arg("zero") = false, pyb::arg("silence_timeout_s") = 3.0,
        pyb::arg("progress") = std::nullopt,
        "Record an ISO 230-4 circular test from a serial port into a rotacal-ballbar/1 file: rows "
        "on a data arc labelled with the run (circular_XY_ccw, ...), the rest 'transition' "
        "(hw/recorder.hpp); progress as for record_ballbar.");
  m.def(
      "record_rtest",
      [](const std::string& port, const std::string& mode, const RtestSession& program,
         double dwell_s, const Array& probe_dirs, const std::string& path, int baud, double rate_hz,
         double speed, double silence_timeout_s, const std::optional<pyb::function>& progress) {
        const Eigen::Matrix3d dirs = matrix3_of(probe_dirs, "probe_dirs");
        const ProbeMode pm = parse_probe_mode(mode);
        const RecordOptions o = record_options(rate_hz, speed, silence_timeout_s, false, progress);
        pyb::gil_scoped_release release;
        auto transport = open_port(port, settings_of(baud));
        return record_rtest(*transport, pm, program, dwell_s, dirs, path, o);
      },
      pyb::arg("port"), pyb::arg("mode"), pyb::arg("program"), pyb::arg("dwell_s"),
      pyb::arg("probe_dirs"), pyb::arg("path"), pyb::arg("baud") = 115200,
      pyb::arg("rate_hz") = 100.0, pyb::arg("speed") = 1.0, pyb::arg("silence_timeout_s") = 3.0,
      pyb::arg("progress") = std::nullopt,
      "Record an R-test (sylvac, keyence or stream mode) into a rotacal-rtest/1 file with raw "
      "d1,d2,d3 (hw/recorder.hpp); progress as for record_ballbar.");
  m.def(
      "list_serial_ports",
      [] {
        std::vector<std::tuple<std::string, std::string, std::string>> out;
        for (const PortInfo& p : list_serial_ports())
          out.emplace_back(p.path, p.description, p.transport);
        return out;
      },
      "(path, description, transport) of every serial port libserialport finds.");
}

}  // namespace rotacal::py::hw_bindings

namespace rotacal::py {
void bind_hw(pyb::module_& m) { hw_bindings::bind(m); }
}  // namespace rotacal::py
#endif  // ROTACAL_WITH_HW
