// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the controllers' compensation tables share (linuxcnc_table.cpp, sinumerik_table.cpp,
// fanuc_table.cpp).
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
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

// The trim (deg) that makes the model's axis reach p (deg): the actual angle of a motor command
// m is m + positioning(m), so t = -positioning(p + t); a contraction for any real error
// (|d positioning / d angle| << 1), four steps leave (n a)^4 a of a harmonic's amplitude a.
inline double trim_deg(const AxisErrorFunction& f, double p_deg) {
  double t = 0.0;
  for (int i = 0; i < 4; ++i) t = -f.evaluate((p_deg + t) / kRadToDeg)[6] * kRadToDeg;
  return t;
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

// The tables `make(f)` of every table axis whose positioning error is not zero, with the error
// motions no table holds; refused for a machine with a head axis (`controller` names whose
// tables) or a model without any positioning error (`nothing_for` says for what).
template <class MakeTable>
CompensationTables positioning_tables(const ModelFile& model,
                                      const std::vector<AxisErrorFunction>& functions,
                                      const std::string& controller, const std::string& nothing_for,
                                      MakeTable make) {
  const MachineType& m = model.machine;
  if (m.has_head())
    throw InvalidArgument("--tables: " + controller +
                          " tables are written for table-table machines; " + to_string(m) +
                          " has an axis on the head");
  CompensationTables out;
  for (const AxisErrorFunction& f : functions) {
    list_not_held(f, m.description().axis(f.chain_index), out);
    if (sample_angle_map(f, -180.0, 180.0, 5.0, 1).max_abs[6] == 0.0) continue;
    out.tables.push_back(make(f));
  }
  if (out.tables.empty())
    throw InvalidArgument("--tables: the model (" + model.kind +
                          ") holds no positioning error of a table axis; nothing for " +
                          nothing_for);
  return out;
}

}  // namespace rotacal::table_detail
