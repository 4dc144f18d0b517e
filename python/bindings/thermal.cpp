// SPDX-License-Identifier: BSD-3-Clause
// Bindings for the thermal test (io/thermal_file.hpp, probe/thermal.hpp, rtest/thermal.hpp,
// session/thermal_summary.hpp): read, identify and summarise a thermal session. Thin: C++
// computes, Python gets the result as a dict.
#include "rotacal/probe/thermal.hpp"

#include <pybind11/stl.h>

#include <map>
#include <optional>
#include <tuple>

#include "json_value.hpp"
#include "numpy.hpp"
#include "rotacal/io/thermal_model.hpp"
#include "rotacal/probe/simulate.hpp"
#include "rotacal/rtest/simulate.hpp"
#include "rotacal/rtest/thermal.hpp"
#include "rotacal/session/thermal_summary.hpp"

namespace rotacal::py {

namespace {

// One lag from Python: (tau_s, gains of the 8 location errors, gains of the table-side point).
using LagArgs = std::tuple<double, Array, Array>;
using DutyArgs = std::vector<std::pair<double, std::map<std::string, double>>>;

ThermalSimSpec thermal_spec(const DutyArgs& duty, const std::vector<double>& epoch_start_s,
                            const std::string& axis, const std::vector<LagArgs>& lags) {
  ThermalSimSpec spec;
  for (const auto& [t, speeds] : duty) {
    DutyEntry d;
    d.time = t;
    for (const auto& [a, v] : speeds) {
      if (a.size() != 1) throw InvalidArgument("simulate_thermal: duty: axis '" + a + "'");
      d.speed.emplace_back(a[0], v);
    }
    spec.duty.push_back(d);
  }
  spec.epoch_start_s = epoch_start_s;
  if (axis.size() != 1) throw InvalidArgument("simulate_thermal: axis '" + axis + "'");
  spec.axis = axis[0];
  for (const auto& [tau, k, kq] : lags) {
    ThermalLagTruth l;
    l.tau_s = tau;
    l.gains.errors = vec_of<8>(k, "lags: gains of the location errors");
    l.gains.point = vec_of<3>(kq, "lags: gains of the table-side point");
    spec.lags.push_back(l);
  }
  return spec;
}

void bind_thermal_simulation(pyb::module_& m) {
  m.def(
      "simulate_thermal",
      [](const std::string& instrument, MachineType machine, const Array& errors,
         const std::vector<std::string>& effects, const std::vector<double>& effect_params,
         const DutyArgs& duty, const std::vector<double>& epoch_start_s, const std::string& axis,
         const std::vector<LagArgs>& lags, const Array& poses_deg, double noise_um, double ar1_rho,
         std::uint64_t seed, const Array& table_points, const Array& sphere_offset,
         double probe_zero_um, double dwell_s) {
        MachineModel t;
        t.machine = machine;
        t.errors = LocationErrors<double>(vec_of<8>(errors, "errors"));
        t.effects = effects_of(effects);
        t.effect_params = effect_params;
        const ThermalSimSpec spec = thermal_spec(duty, epoch_start_s, axis, lags);
        const auto ang = rows_of<2>(poses_deg, "poses_deg");
        std::vector<RotaryAngles<double>> poses;
        for (Eigen::Index i = 0; i < ang.rows(); ++i) poses.push_back({ang(i, 0), ang(i, 1)});
        const std::vector<Eigen::Vector3d> points = vectors_of(table_points, "table_points");
        std::vector<int> epoch;
        pyb::object session;
        Rows3 actual;
        if (instrument == "probe") {
          ProbeSimOptions o;
          o.pattern = default_probe_pattern(machine);
          o.pattern.poses_deg = poses;
          if (points.size() != 1) throw InvalidArgument("simulate_thermal: one sphere centre");
          o.pattern.sphere = points[0];
          o.sphere_offset = vec_of<3>(sphere_offset, "sphere_offset");
          o.noise_um = noise_um, o.ar1_rho = ar1_rho, o.seed = seed, o.thermal = spec;
          ProbeSimulation sim;
          {
            pyb::gil_scoped_release release;
            sim = simulate_probe(t, o);
          }
          epoch = sim.thermal.epoch;
          actual = rows_from({sim.sphere_actual});
          session = pyb::cast(sim.session);
        } else if (instrument == "rtest") {
          RtestSimOptions o;
          o.pattern.poses_deg = poses;
          o.pattern.nests = points;
          o.pattern.dwell_s = dwell_s;
          o.noise_um = noise_um, o.ar1_rho = ar1_rho, o.probe_zero_um = probe_zero_um;
          o.seed = static_cast<unsigned>(seed), o.thermal = spec;
          RtestSimulation sim;
          {
            pyb::gil_scoped_release release;
            sim = simulate_rtest(t, o);
          }
          epoch = sim.thermal.epoch;
          actual = rows_from(sim.probe_zeros);
          session = pyb::cast(sim.session);
        } else {
          throw InvalidArgument("simulate_thermal: instrument '" + instrument +
                                "' (probe or rtest)");
        }
        return pyb::make_tuple(session, epoch, actual);
      },
      pyb::arg("instrument"), pyb::arg("machine"), pyb::arg("errors"), pyb::arg("effects"),
      pyb::arg("effect_params"), pyb::arg("duty"), pyb::arg("epoch_start_s"), pyb::arg("axis"),
      pyb::arg("lags"), pyb::arg("poses_deg"), pyb::arg("noise_um"), pyb::arg("ar1_rho"),
      pyb::arg("seed"), pyb::arg("table_points"), pyb::arg("sphere_offset"),
      pyb::arg("probe_zero_um"), pyb::arg("dwell_s"),
      R"(Simulate a thermal probe or R-test session on rotacal's own simulators.

The pattern (``poses_deg``, (N, 2) tilt and rotary angles in deg) is measured once per epoch
from each of ``epoch_start_s``; between and during them the location errors and the
table-side points drift as ``thermal_location_R`` of ``axis`` (effects.md) driven by ``duty``
(``[(time_s, {axis: rev/min})]``), one or two ``lags`` of (tau_s, 8 gains, 3 point gains).

Parameters
----------
instrument : str
    "probe" (``table_points``: the nominal sphere centre, ``sphere_offset`` its set-up error)
    or "rtest" (``table_points``: the nests, each mounted through the session).
noise_um, ar1_rho : float
    1-sigma noise per coordinate or reading; its AR(1) correlation from row to row.

Returns
-------
tuple
    (session, each row's epoch, the probe's actual sphere centre or the R-test's probe zeros).)");
}

}  // namespace

void bind_thermal(pyb::module_& m) {
  bind_thermal_simulation(m);
  m.def("is_thermal_session", &is_thermal_session, pyb::arg("path"),
        "True when the file has an ``epoch`` column or ``# duty.N:`` lines.");
  m.def(
      "identify_thermal",
      [](const std::string& path, int lags, std::optional<double> tolerance_mm,
         std::optional<double> tolerance_rad, const std::string& noise, bool peer, bool model) {
        nlohmann::ordered_json j;
        {
          pyb::gil_scoped_release release;
          const ThermalSession t = read_thermal_session(path);
          ThermalFitOptions o;
          o.lags = lags;
          o.noise.noise = noise_handling_from_string(noise);
          const ThermalIdentification id =
              std::holds_alternative<ProbeSession>(t.session)
                  ? identify_thermal_probe(std::get<ProbeSession>(t.session), t.thermal, o)
                  : identify_thermal_rtest(std::get<RtestSession>(t.session), t.thermal, o);
          j["identification"] = to_json(id);
          j["summary"] = to_json(thermal_summary(id, {tolerance_mm, tolerance_rad}));
          if (model) j["model"] = thermal_model_document(id, t.thermal.heat_input(id.axis));
          if (peer) {
            if (!std::holds_alternative<ProbeSession>(t.session))
              throw InvalidArgument(path + ": the per-epoch peer is for touch-probe sessions");
            const ThermalIdentification p =
                thermal_peer_probe(std::get<ProbeSession>(t.session), t.thermal, o);
            j["peer"] = {{"identification", to_json(p)},
                         {"summary", to_json(thermal_summary(p, {tolerance_mm, tolerance_rad}))}};
          }
          j["warnings"] = t.warnings;
        }
        return from_json(j);
      },
      pyb::arg("path"), pyb::arg("lags") = 1, pyb::arg("tolerance_mm") = std::nullopt,
      pyb::arg("tolerance_rad") = std::nullopt, pyb::arg("noise") = "auto",
      pyb::arg("peer") = false, pyb::arg("model") = false,
      R"(Identify a thermal probe or R-test session (one joint fit over every row).

Parameters
----------
path : str
    A ``rotacal-probe/1`` or ``rotacal-rtest/1`` file with an ``epoch`` column and
    ``# duty.N:`` lines.
lags : int
    1, or 2 (a fast and a slow lag).
tolerance_mm, tolerance_rad : float, optional
    The drift the user tolerates, for the time from cold after which it may exceed it.
noise : str
    "auto": AR noise model of the residuals, GLS refit when correlated; "white".
peer : bool
    Also the per-epoch peer (touch probe): each epoch identified alone, then one lag fitted
    to the series; under ``peer``, as the joint fit's.
model : bool
    Also the thermal model file's document (``model``; io/thermal_model.hpp), without its
    ``source``.

Returns
-------
dict
    ``identification`` (cold values, each lag's tau and gains with sigma or the reason they
    are unobservable), ``summary`` (steady-state change at the tested speed, significance,
    time to exceed the tolerance, tau), ``warnings``.)");
  m.def(
      "predict_thermal",
      [](const std::string& model_path, const std::string& duty_path,
         std::optional<std::vector<double>> times, double step_s) {
        nlohmann::ordered_json j;
        {
          pyb::gil_scoped_release release;
          const ThermalModel tm = read_thermal_model(model_path);
          const ThermalTest duty = read_duty_file(duty_path, tm.machine);
          for (char a : duty.axes())
            if (a != tm.axis)
              throw InvalidArgument(duty_path + ": the duty turns axis " + std::string(1, a) +
                                    "; the model (" + model_path + ") holds the drift of axis " +
                                    std::string(1, tm.axis) + " only: test that axis' duty too");
          const HeatInput heat = duty.heat_input(tm.axis);
          const std::vector<double> t = times ? *times : thermal_prediction_times(tm, heat, step_s);
          const auto& names = location_error_names(tm.machine);
          j["axis"] = std::string(1, tm.axis);
          j["times_s"] = t;
          j["states"] = nlohmann::ordered_json::array();
          std::vector<nlohmann::ordered_json> value(8), sd(8);
          std::array<bool, 8> known{true, true, true, true, true, true, true, true};
          for (double ti : t) {
            const ThermalErrorsAt e = thermal_errors_at_time(tm, heat, ti);
            j["states"].push_back(e.y);
            for (std::size_t k = 0; k < 8; ++k) {
              value[k].push_back(e.errors.v[static_cast<Eigen::Index>(k)]);
              sd[k].push_back(std::sqrt(e.covariance(k, k)));
              known[k] = known[k] && e.observable[k];
            }
          }
          j["errors"] = nlohmann::ordered_json::array();
          for (std::size_t k = 0; k < 8; ++k)
            j["errors"].push_back(
                {{"name", names[k]},
                 {"unit", location_error_is_angle(static_cast<int>(k)) ? "rad" : "mm"},
                 {"observable", known[k]},
                 {"value", value[k]},
                 {"std", sd[k]}});
        }
        return from_json(j);
      },
      pyb::arg("model_path"), pyb::arg("duty_path"), pyb::arg("times") = std::nullopt,
      pyb::arg("step_s") = 600.0,
      R"(The location errors a thermal model file predicts for a duty (io/thermal_model.hpp).

Parameters
----------
model_path : str
    A thermal model file (``rotacal identify THERMAL.csv --save-model``).
duty_path : str
    A file of ``# duty.N: TIME, AXIS=SPEED, ...`` lines (from cold at 0 s), or a thermal
    session (its duty and epochs, the lag state 0 at its first row).
times : list of float, optional
    s on the duty's clock; default every ``step_s`` to 5 taus after the last entry.

Returns
-------
dict
    ``axis``, ``times_s``, ``states`` (each lag's y per time) and ``errors``: per location
    error ``name``, ``unit``, ``observable``, ``value`` and ``std`` per time (tau's
    uncertainty propagated with the cold values' and the gains').)");
}

}  // namespace rotacal::py
