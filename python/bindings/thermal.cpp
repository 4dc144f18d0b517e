// SPDX-License-Identifier: BSD-3-Clause
// Bindings for the thermal test (io/thermal_file.hpp, probe/thermal.hpp, rtest/thermal.hpp,
// session/thermal_summary.hpp): read, identify and summarise a thermal session. Thin: C++
// computes, Python gets the result as a dict.
#include "rotacal/probe/thermal.hpp"

#include <pybind11/stl.h>

#include <optional>

#include "json_value.hpp"
#include "rotacal/rtest/thermal.hpp"
#include "rotacal/session/thermal_summary.hpp"

namespace rotacal::py {

void bind_thermal(pyb::module_& m) {
  m.def("is_thermal_session", &is_thermal_session, pyb::arg("path"),
        "True when the file has an ``epoch`` column or ``# duty.N:`` lines.");
  m.def(
      "identify_thermal",
      [](const std::string& path, int lags, std::optional<double> tolerance_mm,
         std::optional<double> tolerance_rad, const std::string& noise, bool peer) {
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
      pyb::arg("peer") = false,
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

Returns
-------
dict
    ``identification`` (cold values, each lag's tau and gains with sigma or the reason they
    are unobservable), ``summary`` (steady-state change at the tested speed, significance,
    time to exceed the tolerance, tau), ``warnings``.)");
}

}  // namespace rotacal::py
