// SPDX-License-Identifier: BSD-3-Clause
// The heat input of a thermal test (formats.md "Thermal test of a rotary axis").
#include "rotacal/session/thermal_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rotacal/core/error.hpp"

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

void ThermalSimSpec::validate(MachineType m, double epoch_length_s,
                              const std::string& context) const {
  const auto fail = [&](const std::string& what) { throw InvalidArgument(context + ": " + what); };
  const std::string axes{tilt_axis_letter(m), rot_axis_letter(m)};
  const auto known = [&](char a) { return axes.find(a) != std::string::npos; };
  if (!known(axis))
    fail(std::string("axis ") + axis + ": machine " + to_string(m) + " has rotary axes " + axes[0] +
         ", " + axes[1]);
  if (epoch_start_s.empty()) fail("epoch_start_s: no epoch");
  for (std::size_t e = 0; e < epoch_start_s.size(); ++e) {
    if (!std::isfinite(epoch_start_s[e]) || epoch_start_s[e] < 0.0)
      fail("epoch_start_s: epoch " + std::to_string(e + 1) + " starts before 0 s");
    if (e > 0 && !(epoch_start_s[e] > epoch_start_s[e - 1] + epoch_length_s)) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "epoch_start_s: epoch %zu starts %g s after the one before, which lasts %g s",
                    e + 1, epoch_start_s[e] - epoch_start_s[e - 1], epoch_length_s);
      fail(buf);
    }
  }
  for (std::size_t i = 0; i < duty.size(); ++i) {
    const std::string n = "duty." + std::to_string(i + 1);
    if (!(duty[i].time >= 0.0) || (i > 0 && !(duty[i].time > duty[i - 1].time)))
      fail(n + ": TIME must be >= 0 and strictly increasing");
    for (const auto& s : duty[i].speed)
      if (!known(s.first) || !std::isfinite(s.second))
        fail(n + ": axis " + std::string(1, s.first) + " is not a rotary axis of " + to_string(m) +
             " or its speed is not a number");
  }
  if (lags.size() > 2) fail("at most two lags of one axis");
  for (const ThermalLagTruth& l : lags)
    if (!(l.tau_s > 0.0) || !std::isfinite(l.tau_s)) fail("a lag's tau_s must be > 0");
}

ThermalTest ThermalSimSpec::test(const std::vector<double>& time,
                                 const std::vector<int>& epoch) const {
  ThermalTest t;
  t.duty = duty;
  t.time = time;
  t.epoch = epoch;
  return t;
}

std::vector<std::vector<double>> ThermalSimSpec::lag_states(const ThermalTest& test) const {
  const HeatInput heat = test.heat_input(axis);
  std::vector<std::vector<double>> out;
  for (const ThermalLagTruth& l : lags)
    out.push_back(rotacal::lag_states(heat, test.time, l.tau_s));
  return out;
}

LocationErrors<double> ThermalSimSpec::errors_at(const LocationErrors<double>& cold,
                                                 const std::vector<std::vector<double>>& states,
                                                 std::size_t i) const {
  LocationErrors<double> e = cold;
  for (std::size_t l = 0; l < lags.size(); ++l) e = drifted_errors(e, lags[l].gains, states[l][i]);
  return e;
}

Eigen::Vector3d ThermalSimSpec::point_at(const Eigen::Vector3d& cold,
                                         const std::vector<std::vector<double>>& states,
                                         std::size_t i) const {
  Eigen::Vector3d q = cold;
  for (std::size_t l = 0; l < lags.size(); ++l) q = drifted_point(q, lags[l].gains, states[l][i]);
  return q;
}

}  // namespace rotacal
