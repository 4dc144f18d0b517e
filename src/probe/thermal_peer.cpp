// SPDX-License-Identifier: BSD-3-Clause
// The per-epoch peer of a thermal probe session (probe/thermal.hpp, session/thermal_series.hpp).
#include "rotacal/probe/identify.hpp"
#include "rotacal/probe/thermal.hpp"
#include "rotacal/session/thermal_series.hpp"

namespace rotacal {

ThermalIdentification thermal_peer_probe(const ProbeSession& session, const ThermalTest& thermal,
                                         const ThermalFitOptions& options) {
  const std::vector<char> axes = thermal.axes();
  if (axes.size() > 1)
    throw InvalidArgument("per-epoch peer: the duty turns " + std::to_string(axes.size()) +
                          " axes; one thermal_location_R at a time is supported");
  if (thermal.epoch.size() != session.samples.size())
    throw InvalidArgument("per-epoch peer: the thermal test has " +
                          std::to_string(thermal.epoch.size()) + " rows for " +
                          std::to_string(session.samples.size()) + " touches");
  const auto& names = location_error_names(session.machine);
  std::vector<ThermalSeries> series;
  for (int k = 0; k < 11; ++k) {
    ThermalSeries s;
    s.name = k < 8 ? names[static_cast<std::size_t>(k)] : std::string("q_") + "xyz"[k - 8];
    s.unit = k < 8 && location_error_is_angle(k) ? "rad" : "mm";
    series.push_back(s);
  }
  std::vector<double> t_mid;
  ProbeFitOptions po;  // white: 40 touches or so per epoch leave no stream to model
  for (const auto& span : thermal.epoch_spans()) {
    ProbeSession epoch = session;
    epoch.samples.clear();
    for (std::size_t i = 0; i < session.samples.size(); ++i)
      if (thermal.time[i] >= span.first && thermal.time[i] <= span.second)
        epoch.samples.push_back(session.samples[i]);
    const ProbeIdentification id = identify_probe(epoch, po);
    t_mid.push_back(0.5 * (span.first + span.second));
    for (int k = 0; k < 11; ++k) {
      const ParameterEstimate& p = id.parameter(k < 8 ? names[static_cast<std::size_t>(k)]
                                                      : std::string("sphere.") + "xyz"[k - 8]);
      const bool ok = p.observable && p.std > 0.0;
      series[static_cast<std::size_t>(k)].value.push_back(ok ? p.value : 0.0);
      series[static_cast<std::size_t>(k)].std.push_back(ok ? p.std : 0.0);
    }
  }
  ThermalIdentification out =
      fit_lag_to_series(series, t_mid, thermal, axes.empty() ? 0 : axes.front(), options);
  out.machine = session.machine;
  out.n_samples = session.samples.size();
  return out;
}

}  // namespace rotacal
