// SPDX-License-Identifier: BSD-3-Clause
// The heat input of a thermal test (formats.md "Thermal test of a rotary axis").
#include "rotacal/session/thermal_test.hpp"

#include <algorithm>
#include <cmath>

namespace rotacal {

std::vector<char> ThermalTest::axes() const {
  std::vector<char> out;
  for (const DutyEntry& d : duty)
    for (const auto& s : d.speed)
      if (s.second != 0.0 && std::find(out.begin(), out.end(), s.first) == out.end())
        out.push_back(s.first);
  return out;
}

std::vector<std::pair<double, double>> ThermalTest::epoch_spans() const {
  std::vector<std::pair<double, double>> out;
  for (std::size_t i = 0; i < epoch.size(); ++i) {
    if (i == 0 || epoch[i] != epoch[i - 1])
      out.emplace_back(time[i], time[i]);
    else
      out.back().second = time[i];
  }
  return out;
}

HeatInput ThermalTest::heat_input(char axis) const {
  HeatInput out;
  if (time.empty()) return out;
  const double t0 = time.front(), t1 = time.back();
  std::vector<double> cuts{t0};
  for (const DutyEntry& d : duty)
    if (d.time > t0 && d.time < t1) cuts.push_back(d.time);
  const auto spans = epoch_spans();
  for (const auto& s : spans)
    for (double c : {s.first, s.second})
      if (c > t0 && c < t1) cuts.push_back(c);
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    // u on [cuts[i], cuts[i+1]): the duty entry in force there, 0 inside an epoch. An epoch
    // of one row has no length and holds nothing.
    const double a = cuts[i];
    const double b = i + 1 < cuts.size() ? cuts[i + 1] : a + 1.0;
    const double mid = 0.5 * (a + b);
    double u = 0.0;
    for (const DutyEntry& d : duty)
      if (d.time <= mid) u = std::abs(d.speed_of(axis)) / 100.0;
    for (const auto& s : spans)
      if (s.first <= mid && mid <= s.second) u = 0.0;
    if (!out.u.empty() && out.u.back() == u) continue;  // merge equal neighbours
    out.start.push_back(a);
    out.u.push_back(u);
  }
  return out;
}

double ThermalTest::tested_speed(char axis) const {
  double v = 0.0;
  for (const DutyEntry& d : duty) v = std::max(v, std::abs(d.speed_of(axis)));
  return v;
}

}  // namespace rotacal
