// SPDX-License-Identifier: BSD-3-Clause
// ISG/Beckhoff compensation value lists: leadscrew error compensation (kw.ssfk) of each table
// axis' positioning error, cross compensation (kw.crosscomp) of its translations in the linear
// (slave) axes' lists (angle_map.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/io/compensation_table.hpp"
#include "rotacal/io/controller_export.hpp"
#include "shared.hpp"
#include "table_shared.hpp"

namespace rotacal {

namespace isg_table_detail {

using namespace table_detail;

constexpr double kUnitDeg = 1e-4;  // R axes: 0.0001 deg (P-COMP-00019, P-COMP-00017)
constexpr double kUnitMm = 1e-4;   // T axes: 0.1 um

long whole(double v, double unit) { return std::lround(v / unit); }

// The logical axis number (kopf / P-COMP-00005) of an axis letter.
int axis_number(char letter, const CompensationTableOptions& o) {
  const auto it = o.isg_axis_numbers.find(letter);
  if (it != o.isg_axis_numbers.end()) return it->second;
  static const std::string order = "XYZABC";
  return static_cast<int>(order.find(letter)) + 1;
}

std::string model_line(const ExportInput& in) {
  return "model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path) +
         (in.source.empty() ? "" : "; identified from " + in.source);
}

// kw.ssfk of axis f: equidistant, bilateral (the same values both ways: the model's positioning
// does not depend on the direction), modulo over one turn for an endless axis without a range.
CompensationTable ssfk_table(const AxisErrorFunction& f, const MachineType& m,
                             const CompensationTableOptions& o, const ExportInput& in) {
  const RotaryAxis& ax = m.description().axis(f.chain_index);
  const std::string letter(1, f.axis);
  const auto [lo, hi, modulo] = span_of(f, ax, o);
  CompensationTable t;
  t.axis = f.axis;
  t.joint = -1;
  t.holds = positioning_sources(f, ax);
  t.file_name = "ssfk_" + letter + ".lis";
  t.nominal_deg = equally_spaced_deg(lo, hi, o.spacing_deg,
                                     modulo ? "--spacing (a modulo table spans 360 deg)"
                                            : "--table-range " + letter + " / --spacing");
  const std::size_t n = t.nominal_deg.size(), max_points = o.max_points ? o.max_points : 1500;
  if (n > max_points)
    throw InvalidArgument("--tables: ISG's kw.ssfk holds at most " + std::to_string(max_points) +
                          " entries (kw_nr_max, P-COMP-00020; P-COMP-00059 as configured; "
                          "--max-points); the " +
                          letter + " table every " + export_detail::fixed(o.spacing_deg, 3) +
                          " deg has " + std::to_string(n) + ": use a larger --spacing");
  // The value at commanded position p is the error there, actual - commanded, as the control
  // takes it off the setpoint: -trim(p), the motor command that reaches p being p + trim(p).
  const auto value = [&](double p) { return -trim_deg(f, p); };
  std::vector<long> q;
  for (const double p : t.nominal_deg) q.push_back(whole(value(p), kUnitDeg));
  if (modulo) q.back() = q.front();  // the modulo transition: first and last entry agree
  for (const long v : q) t.value_deg.push_back(static_cast<double>(v) * kUnitDeg);
  t.max_interpolation_error_deg =
      worst_interpolation_error(t.nominal_deg, t.value_deg, value, o.samples_between);
  const double err = t.max_interpolation_error_deg;
  export_detail::Writer w(CommentDialect::hash);
  w.line("rotacal export: ISG leadscrew error compensation (kw.ssfk) of axis " + letter +
         " (logical axis " + std::to_string(axis_number(f.axis, o)) +
         "), values in 0.0001 deg; activate with lr_param.ssfk = 1 (P-AXIS-00175)");
  w.line("holds: positioning_" + letter + " (actual - commanded angle) from " +
         joined(t.holds, "no term of the model"));
  w.line(
      "sign: value = actual - commanded position (an absolute position error, as ISG's "
      "measured lists): the control takes it off the setpoint, so a positive value moves the "
      "axis negative");
  w.line("points: " + std::to_string(n) + " every " + export_detail::fixed(o.spacing_deg, 6) +
         " deg from " + export_detail::fixed(lo, 6) + " to " + export_detail::fixed(hi, 6) +
         " deg" +
         (modulo ? ", modulo (kw.ssfk.modulo: the table repeats every turn)"
                 : "; beyond them the end values hold: correction stops there") +
         "; the same values in both directions (bilateral)");
  w.line("worst interpolation error between points: " + rounded_up(err) + " deg (" +
         rounded_up(err / kRadToDeg * 1e6) + " urad; the model evaluated at " +
         std::to_string(o.samples_between) + " angles inside each interval, with the rounding)");
  for (const std::string& note : f.notes) w.line("left out: " + note);
  w.line(model_line(in));
  w.line("written: " + (o.generated_at.empty() ? table_written_at() : o.generated_at));
  std::ostringstream out;
  out << w.out.str() << "kw.ssfk.unit  1\nkw.ssfk.interval  " << whole(o.spacing_deg, kUnitDeg)
      << "\nkw.ssfk.kw_startpos  " << whole(lo, kUnitDeg) << "\nkw.ssfk.kw_nr_max  " << n
      << "\nkw.ssfk.bilateral  1\nkw.ssfk.modulo  " << (modulo ? 1 : 0) << "\n";
  for (std::size_t i = 0; i < n; ++i) out << "kw.ssfk.table[" << i << "].pos  " << q[i] << "\n";
  for (std::size_t i = 0; i < n; ++i) out << "kw.ssfk.table[" << i << "].neg  " << q[i] << "\n";
  t.text = out.str();
  t.summary = "axis " + letter + " positioning (kw.ssfk), " + std::to_string(n) + " points over " +
              export_detail::fixed(lo, 3) + ".." + export_detail::fixed(hi, 3) + " deg" +
              (modulo ? " modulo" : "") + ", worst interpolation error " +
              rounded_up(err / kRadToDeg * 1e6) + " urad";
  return t;
}

// The cross compensation of slave `slave` (X, Y or Z) with master f: the master's translation
// along the slave over its range (no modulo: kw.crosscomp has none), in 0.1 um.
CompensationTable crosscomp_table(const AxisErrorFunction& f, int j, const MachineType& m,
                                  const CompensationTableOptions& o, const ExportInput& in,
                                  const std::string& others) {
  const RotaryAxis& ax = m.description().axis(f.chain_index);
  const char slave = "XYZ"[j];
  const std::string letter(1, f.axis), s(1, slave);
  const auto [lo, asked_hi] = range_of(ax, o);
  const double hi = lo + std::ceil((asked_hi - lo) / o.spacing_deg - 1e-9) * o.spacing_deg;
  CompensationTable t;
  t.axis = f.axis;
  t.joint = -1;
  t.holds = translation_sources(f);
  t.file_name = "crosscomp_" + s + ".lis";
  t.nominal_deg = equally_spaced_deg(lo, hi, o.spacing_deg, "--table-range " + letter);
  const std::size_t n = t.nominal_deg.size(),
                    max_points = o.max_cross_points ? o.max_cross_points : 1000;
  if (n > max_points)
    throw InvalidArgument("--tables: ISG's kw.crosscomp holds at most " +
                          std::to_string(max_points) +
                          " values (kw.crosscomp.table, P-COMP-00060 as configured; "
                          "--max-cross-points); the " +
                          letter + " -> " + s + " table has " + std::to_string(n) +
                          ": use a larger --spacing or a shorter --table-range");
  const auto value = [&](double x) { return f.evaluate(x / kRadToDeg)[j]; };
  std::vector<double>& v = t.value_mm[slave];
  std::vector<long> q;
  for (const double x : t.nominal_deg) {
    q.push_back(whole(value(x), kUnitMm));
    v.push_back(static_cast<double>(q.back()) * kUnitMm);
  }
  t.max_interpolation_error_mm =
      worst_interpolation_error(t.nominal_deg, v, value, o.samples_between);
  const double err = t.max_interpolation_error_mm;
  export_detail::Writer w(CommentDialect::hash);
  w.line("rotacal export: ISG cross compensation (kw.crosscomp) of slave axis " + s +
         " (logical axis " + std::to_string(axis_number(slave, o)) + ") by master axis " + letter +
         " (logical axis " + std::to_string(axis_number(f.axis, o)) +
         "), corrections in 0.1 um; activate with lr_param.crosscomp = 1 (P-AXIS-00047)");
  w.line("holds: E_" + s + letter + " (the translation of " + letter + "'s frame along " + s +
         ") from " + joined(t.holds, "no named term of the model"));
  w.line(
      "sign: correction = the translation of the table point, added to the slave's position: "
      "the tool follows the point");
  w.line("points: " + std::to_string(n) + " every " + export_detail::fixed(o.spacing_deg, 6) +
         " deg of " + letter + " over " + export_detail::fixed(lo, 6) + ".." +
         export_detail::fixed(hi, 6) + " deg; correction stops outside");
  w.line("worst interpolation error between points: " + rounded_up(err) + " mm (" +
         rounded_up(err * 1e3) + " um, with the rounding)");
  if (!others.empty())
    w.line("not held: " + others + " (a slave's list holds one master's cross compensation)");
  std::array<double, 2> tilt_range{0.0, 0.0};
  const double remains = tilt_remains_mm(f, m, o, t.nominal_deg, tilt_range);
  if (remains > 0.0)
    w.line("held at " + std::string(1, m.description().axis(m.tilt_index()).name) +
           " = 0 only: away from it the translation turns with the tilt, and up to " +
           export_detail::fixed(remains * 1e3, 3) + " um (of all three components) remains over " +
           export_detail::fixed(tilt_range[0], 3) + ".." + export_detail::fixed(tilt_range[1], 3) +
           " deg, left to rotacal compensate");
  w.line(model_line(in));
  w.line("written: " + (o.generated_at.empty() ? table_written_at() : o.generated_at));
  std::ostringstream out;
  out << w.out.str() << "kw.crosscomp.master_ax_nr  " << axis_number(f.axis, o)
      << "\nkw.crosscomp.unit  1\nkw.crosscomp.last_index  " << n - 1 << "\n";
  for (std::size_t i = 0; i < n; ++i)
    out << "kw.crosscomp.table[" << i << "].sollw  " << whole(t.nominal_deg[i], kUnitDeg)
        << "\nkw.crosscomp.table[" << i << "].correction  " << q[i] << "\n";
  t.text = out.str();
  t.summary = "slave " + s + " by master " + letter + " (kw.crosscomp), " + std::to_string(n) +
              " points, worst interpolation error " + rounded_up(err * 1e3) + " um";
  return t;
}

}  // namespace isg_table_detail

CompensationTables isg_tables(const ModelFile& model,
                              const std::vector<AxisErrorFunction>& functions,
                              const CompensationTableOptions& o) {
  using namespace isg_table_detail;
  if (std::abs(o.spacing_deg / kUnitDeg - std::round(o.spacing_deg / kUnitDeg)) > 1e-6)
    throw InvalidArgument(
        "--spacing: ISG's positions (kw.ssfk.interval, kw.crosscomp sollw) are whole numbers of "
        "0.0001 deg");
  const ExportInput in = export_input(model, o.model_path);
  // Each slave's master: the axis with the largest translation along it; the others' are listed.
  std::array<std::size_t, 3> master{functions.size(), functions.size(), functions.size()};
  std::array<double, 3> size{0.0, 0.0, 0.0};
  std::array<std::string, 3> others;
  for (std::size_t k = 0; k < functions.size(); ++k)
    for (std::size_t j = 0; j < 3; ++j)
      if (largest_terms(functions[k])[static_cast<int>(j)] > size[j]) {
        size[j] = largest_terms(functions[k])[static_cast<int>(j)];
        master[j] = k;
      }
  for (std::size_t k = 0; k < functions.size(); ++k)
    for (std::size_t j = 0; j < 3; ++j)
      if (k != master[j] && largest_terms(functions[k])[static_cast<int>(j)] > 0.0)
        others[j] += (others[j].empty() ? "" : ", ") + functions[k].names[j];
  CompensationTables out = axis_tables(
      model, functions, "ISG", "kw.ssfk or kw.crosscomp", true, [&](const AxisErrorFunction& f) {
        std::vector<CompensationTable> t;
        if (largest_terms(f)[6] != 0.0) t.push_back(ssfk_table(f, model.machine, o, in));
        for (int j = 0; j < 3; ++j)
          if (master[static_cast<std::size_t>(j)] < functions.size() &&
              functions[master[static_cast<std::size_t>(j)]].chain_index == f.chain_index)
            t.push_back(
                crosscomp_table(f, j, model.machine, o, in, others[static_cast<std::size_t>(j)]));
        return t;
      });
  for (int j = 0; j < 3; ++j)
    if (!others[static_cast<std::size_t>(j)].empty())
      out.not_held.push_back(others[static_cast<std::size_t>(j)] +
                             " (ISG: one master per slave's cross compensation)");
  return out;
}

}  // namespace rotacal
