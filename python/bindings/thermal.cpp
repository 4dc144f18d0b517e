// SPDX-License-Identifier: BSD-3-Clause
// Bindings for the thermal test (io/thermal_file.hpp, probe/thermal.hpp, rtest/thermal.hpp,
// session/thermal_summary.hpp): read, identify and summarise a thermal session. Thin: C++
// computes, Python gets the result as a dict.
#include "rotacal/probe/thermal.hpp"

#include <pybind11/stl.h>

#include <optional>

#include "json_value.hpp"
#include "rotacal/io/thermal_model.hpp"
#include "rotacal/rtest/thermal.hpp"
#include "rotacal/session/thermal_summary.hpp"

namespace rotacal::py {

void bind_thermal(pyb::module_& m) {
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
