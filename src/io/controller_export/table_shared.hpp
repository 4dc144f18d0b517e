// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the controllers' compensation tables share (linuxcnc_table.cpp, sinumerik_table.cpp,
// fanuc_table.cpp).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/io/compensation_table.hpp"
#include "rotacal/io/controller_export.hpp"

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

// The positions a table of axis ax spans: an endless axis without a range gets a modulo table
// over one turn (K3, ISG: 0 to 360 deg); else its range, up to the first point at or past its end.
struct Span {
  double lo = 0.0, hi = 0.0;
  bool modulo = false;
};

inline Span span_of(const AxisErrorFunction& f, const RotaryAxis& ax,
                    const CompensationTableOptions& o) {
  Span s;
  s.modulo = !ax.limits_deg && !o.range_deg.count(f.axis);
  const auto [lo, asked_hi] = s.modulo ? std::array<double, 2>{0.0, 360.0} : range_of(ax, o);
  s.lo = lo;
  s.hi = !s.modulo && o.spacing_deg > 0.0 && asked_hi > lo
             ? lo + std::ceil((asked_hi - lo) / o.spacing_deg - 1e-9) * o.spacing_deg
             : asked_hi;
  return s;
}

inline std::string joined(const std::vector<std::string>& v, const std::string& none) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? none : s;
}

// The model terms that feed an axis' translations E_X, E_Y, E_Z at its nominal point: radial
// and axial motions, a tilting table's sag, an R-test map's dx, dy, dz.
inline std::vector<std::string> translation_sources(const AxisErrorFunction& f) {
  std::vector<std::string> out;
  for (const std::string& s : f.sources)
    for (const char* p : {"radial_motion", "axial_motion", "gravity_sag", "dx_", "dy_", "dz_"})
      if (s.rfind(p, 0) == 0) out.push_back(s);
  return out;
}

// The largest absolute value of each term over a turn (every 5 deg): which terms an axis has.
inline AngleMapTerms largest_terms(const AxisErrorFunction& f) {
  return sample_angle_map(f, -180.0, 180.0, 5.0, 1).max_abs;
}

// The model's error motions of an axis that no table of this controller holds, with their largest
// value; the rotation about the axis' own principal direction is its positioning, which the
// tables hold, and with `translations` its E_X, E_Y, E_Z go to cross tables too.
inline void list_not_held(const AxisErrorFunction& f, const RotaryAxis& ax, bool translations,
                          CompensationTables& out) {
  const AxisAngleMap map = sample_angle_map(f, -180.0, 180.0, 5.0, 1);
  for (int j = 0; j < 6; ++j)
    if (map.max_abs[j] > 0.0 && j != 3 + ax.principal && !(translations && j < 3)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, " up to %.3f %s", map.max_abs[j] * (j < 3 ? 1e3 : 1e6),
                    j < 3 ? "um" : "urad");
      out.not_held.push_back(map.names[static_cast<std::size_t>(j)] + buf +
                             (translations ? " (no table of this controller holds an angular "
                                             "error motion)"
                                           : " (a table holds no error motion)"));
    }
}

// What remains of the rotary axis' translation E(x) at tilt t, where it is R(t) E(x) but the
// tables (no $AN_CEC_MULT_BY_TABLE) give E(x): the largest (R(t) - I) E(x) over the tilt axis'
// range and the table points, mm. 0 for the tilt axis (the frame it is mounted in is fixed).
inline double tilt_remains_mm(const AxisErrorFunction& f, const MachineType& m,
                              const CompensationTableOptions& o,
                              const std::vector<double>& grid_deg,
                              std::array<double, 2>& tilt_range) {
  if (f.chain_index != m.rot_index() || m.description().table_axes.size() < 2) return 0.0;
  const RotaryAxis& tilt = m.description().axis(m.tilt_index());
  tilt_range = range_of(tilt, o);
  std::vector<Eigen::Vector3d> e;
  for (const double x : grid_deg) e.push_back(f.evaluate(x / kRadToDeg).head<3>());
  double worst = 0.0;
  for (double t = tilt_range[0]; t <= tilt_range[1] + 1e-9; t += 1.0) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(t / kRadToDeg, tilt.direction.normalized()).toRotationMatrix() -
        Eigen::Matrix3d::Identity();
    for (const Eigen::Vector3d& v : e) worst = std::max(worst, (R * v).norm());
  }
  return worst;
}

// The one loop over a model's table axes: `make(f)` gives each axis' tables (none, one, or a
// positioning table and its cross tables), with the error motions no table holds listed;
// refused for a machine with a head axis (`controller` names whose tables) or a model for which
// no table is written (`nothing_for` says for what). `translations`: the controller's cross
// tables hold the axes' E_X, E_Y, E_Z.
template <class MakeTables>
CompensationTables axis_tables(const ModelFile& model,
                               const std::vector<AxisErrorFunction>& functions,
                               const std::string& controller, const std::string& nothing_for,
                               bool translations, MakeTables make) {
  const MachineType& m = model.machine;
  if (m.has_head())
    throw InvalidArgument("--tables: " + controller +
                          " tables are written for table-table machines; " + to_string(m) +
                          " has an axis on the head");
  CompensationTables out;
  for (const AxisErrorFunction& f : functions) {
    list_not_held(f, m.description().axis(f.chain_index), translations, out);
    for (CompensationTable& t : make(f)) out.tables.push_back(std::move(t));
  }
  if (out.tables.empty())
    throw InvalidArgument(
        "--tables: the model (" + model.kind + ") holds no " +
        (translations ? "positioning error or translation" : "positioning error") +
        " of a table axis; nothing for " + nothing_for);
  return out;
}

// The table `make(f)` of every table axis whose positioning error is not zero.
template <class MakeTable>
CompensationTables positioning_tables(const ModelFile& model,
                                      const std::vector<AxisErrorFunction>& functions,
                                      const std::string& controller, const std::string& nothing_for,
                                      MakeTable make) {
  return axis_tables(model, functions, controller, nothing_for, false,
                     [&](const AxisErrorFunction& f) {
                       std::vector<CompensationTable> t;
                       if (largest_terms(f)[6] != 0.0) t.push_back(make(f));
                       return t;
                     });
}

// The same as the entry function every positioning writer shares: the export input of the
// model, and `one(f, machine, options, input)` for each axis.
template <class OneTable>
CompensationTables positioning_tables(const ModelFile& model,
                                      const std::vector<AxisErrorFunction>& functions,
                                      const CompensationTableOptions& o,
                                      const std::string& controller, const std::string& nothing_for,
                                      OneTable one) {
  const ExportInput in = export_input(model, o.model_path);
  return positioning_tables(
      model, functions, controller, nothing_for,
      [&](const AxisErrorFunction& f) { return one(f, model.machine, o, in); });
}

}  // namespace rotacal::table_detail
