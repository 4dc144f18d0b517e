// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the controllers' compensation tables share (linuxcnc_table.cpp, sinumerik_table.cpp).
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "rotacal/io/compensation_table.hpp"

namespace rotacal::table_detail {

constexpr double kRadToDeg = 180.0 / M_PI;

// The time of the export, UTC ISO 8601 (as the kinematic exports' header writes it).
inline std::string table_written_at() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// v with 4 significant digits, rounded up (a stated error is never below the one found).
inline std::string rounded_up(double v) {
  if (!(v > 0.0)) return "0";
  const double step = std::pow(10.0, std::floor(std::log10(v)) - 3);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", std::ceil(v / step - 1e-9) * step);
  return buf;
}

// The model terms that feed the positioning error: the effects of the axis' angle, or the
// R-test map's rotation about the axis (gamma_CB of a C, beta_BY of a B).
inline std::vector<std::string> positioning_sources(const AxisErrorFunction& f,
                                                    const RotaryAxis& ax) {
  static const char* rotation[3] = {"alpha_", "beta_", "gamma_"};
  std::vector<std::string> out;
  for (const std::string& s : f.sources)
    if (s.rfind("rotary_zero_offset", 0) == 0 || s.rfind("angular_positioning", 0) == 0 ||
        (ax.principal >= 0 && s.rfind(rotation[ax.principal], 0) == 0))
      out.push_back(s);
  return out;
}

inline std::array<double, 2> range_of(const RotaryAxis& ax, const CompensationTableOptions& o) {
  const auto it = o.range_deg.find(ax.name);
  if (it != o.range_deg.end()) return it->second;
  if (ax.limits_deg) return *ax.limits_deg;
  return {-360.0, 360.0};
}

inline std::string joined(const std::vector<std::string>& v, const std::string& none) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? none : s;
}

// The model's error motions of an axis (no table holds them), with their largest value; the
// rotation about the axis' own principal direction is its positioning, which the table holds.
inline void list_not_held(const AxisErrorFunction& f, const RotaryAxis& ax,
                          CompensationTables& out) {
  const AxisAngleMap map = sample_angle_map(f, -180.0, 180.0, 5.0, 1);
  for (int j = 0; j < 6; ++j)
    if (map.max_abs[j] > 0.0 && j != 3 + ax.principal) {
      char buf[64];
      std::snprintf(buf, sizeof buf, " up to %.3f %s", map.max_abs[j] * (j < 3 ? 1e3 : 1e6),
                    j < 3 ? "um" : "urad");
      out.not_held.push_back(map.names[static_cast<std::size_t>(j)] + buf +
                             " (a table holds no error motion)");
    }
}

}  // namespace rotacal::table_detail
