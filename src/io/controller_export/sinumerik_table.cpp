// SPDX-License-Identifier: BSD-3-Clause
// SINUMERIK encoder / leadscrew error compensation ($AA_ENC_COMP) of each table axis'
// positioning error, and cross error compensation ($AN_CEC) of its translations (angle_map.hpp).
#include <algorithm>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/io/compensation_table.hpp"
#include "rotacal/io/controller_export.hpp"
#include "shared.hpp"
#include "table_shared.hpp"

namespace rotacal {

namespace sinumerik_table_detail {

using namespace table_detail;

// A machine axis identifier (MD10000): a letter, then letters, digits or _.
std::string axis_name(char letter, const CompensationTableOptions& o) {
  const auto it = o.axis_names.find(letter);
  const std::string name = it != o.axis_names.end() ? it->second : std::string(1, letter) + "1";
  bool ok = !name.empty() && name.size() <= 32 && name[0] >= 'A' && name[0] <= 'Z';
  for (const char c : name)
    ok = ok && ((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
  if (!ok)
    throw InvalidArgument("--siemens-axis " + std::string(1, letter) +
                          ": a machine axis identifier is A-Z, then A-Z, 0-9 or _ (MD10000)");
  return name;
}

CompensationTable one_table(const AxisErrorFunction& f, const MachineType& m,
                            const CompensationTableOptions& o, const ExportInput& in) {
  const RotaryAxis& ax = m.description().axis(f.chain_index);
  const std::string letter(1, f.axis), name = axis_name(f.axis, o);
  const auto [lo, hi, modulo] = span_of(f, ax, o);
  CompensationTable t;
  t.axis = f.axis;
  t.holds = positioning_sources(f, ax);
  t.joint = -1;
  t.file_name = "eec_" + letter + ".mpf";
  t.nominal_deg = equally_spaced_deg(lo, hi, o.spacing_deg,
                                     modulo ? "--spacing (a modulo table spans 360 deg)"
                                            : "--table-range " + letter + " / --spacing");
  const std::size_t max_points = o.max_points ? o.max_points : 200;
  if (t.nominal_deg.size() > max_points)
    throw InvalidArgument(
        "--tables: the SINUMERIK table holds at most " + std::to_string(max_points) +
        " interpolation points (MD38000 $MA_MM_ENC_COMP_MAX_POINTS as configured; --max-points); "
        "the " +
        letter + " table over " + export_detail::fixed(lo, 3) + ".." + export_detail::fixed(hi, 3) +
        " deg every " + export_detail::fixed(o.spacing_deg, 3) + " deg has " +
        std::to_string(t.nominal_deg.size()) + ": use a larger --spacing");
  // The value at axis position x is the positioning error there: the control corrects the
  // actual value by it, so a positive value moves the axis negative by it.
  const auto value = [&](double x) { return f.evaluate(x / kRadToDeg)[6] * kRadToDeg; };
  for (const double x : t.nominal_deg) t.value_deg.push_back(value(x));
  t.max_interpolation_error_deg =
      worst_interpolation_error(t.nominal_deg, t.value_deg, value, o.samples_between);
  const double err = t.max_interpolation_error_deg;
  std::ostringstream out;
  out << "%_N_AX_EEC_INI\nCHANDATA(1)\n";
  export_detail::Writer w(CommentDialect::siemens);
  w.line("rotacal export: SINUMERIK encoder/leadscrew error compensation (EEC) of axis " + letter +
         " (machine axis " + name + "), values in deg");
  w.line("holds: positioning_" + letter + " (actual - commanded angle) from " +
         joined(positioning_sources(f, ax), "no term of the model"));
  w.line(
      "sign: value = actual - commanded angle at the axis position: the control corrects the "
      "actual value by it, a positive value moves the axis negative (K3)");
  w.line("points: " + std::to_string(t.nominal_deg.size()) + " every " +
         export_detail::fixed(o.spacing_deg, 6) + " deg over " + export_detail::fixed(lo, 6) +
         ".." + export_detail::fixed(hi, 6) + " deg" +
         (modulo ? ", modulo (the table repeats every turn)"
                 : "; beyond them the end values hold: correction stops there") +
         "; MD38000 must be >= " + std::to_string(t.nominal_deg.size()) +
         ", MD32700 ENC_COMP_ENABLE = 0 while loading, 1 after");
  w.line("worst interpolation error between points: " + rounded_up(err) + " deg (" +
         rounded_up(err / kRadToDeg * 1e6) + " urad; the model evaluated at " +
         std::to_string(o.samples_between) + " angles inside each interval)");
  for (const std::string& n : f.notes) w.line("left out: " + n);
  w.line("model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path) +
         (in.source.empty() ? "" : "; identified from " + in.source));
  w.line("written: " + (o.generated_at.empty() ? table_written_at() : o.generated_at));
  out << w.out.str();
  for (std::size_t i = 0; i < t.value_deg.size(); ++i)
    out << "$AA_ENC_COMP[0," << i << "," << name << "]=" << export_detail::fixed(t.value_deg[i], 9)
        << "\n";
  out << "$AA_ENC_COMP_STEP[0," << name << "]=" << export_detail::fixed(o.spacing_deg, 6) << "\n"
      << "$AA_ENC_COMP_MIN[0," << name << "]=" << export_detail::fixed(lo, 6) << "\n"
      << "$AA_ENC_COMP_MAX[0," << name << "]=" << export_detail::fixed(hi, 6) << "\n"
      << "$AA_ENC_COMP_IS_MODULO[0," << name << "]=" << (modulo ? 1 : 0) << "\nM17\n";
  t.text = out.str();
  t.summary = "axis " + letter + " positioning (EEC of " + name + "), " +
              std::to_string(t.nominal_deg.size()) + " points over " + export_detail::fixed(lo, 3) +
              ".." + export_detail::fixed(hi, 3) + " deg" + (modulo ? " modulo" : "") +
              ", worst interpolation error " + rounded_up(err / kRadToDeg * 1e6) + " urad";
  return t;
}

// One CEC program of axis f's translations: a table per output axis X, Y, Z that moves, numbered
// from next_table on.
CompensationTable cec_file(const AxisErrorFunction& f, const MachineType& m,
                           const CompensationTableOptions& o, const ExportInput& in,
                           int& next_table, std::vector<std::string>& not_held) {
  const RotaryAxis& ax = m.description().axis(f.chain_index);
  const std::string letter(1, f.axis), name = axis_name(f.axis, o);
  const auto [lo, hi, modulo] = span_of(f, ax, o);
  CompensationTable t;
  t.axis = f.axis;
  t.joint = -1;
  t.holds = translation_sources(f);
  t.file_name = "cec_" + letter + ".mpf";
  t.nominal_deg = equally_spaced_deg(lo, hi, o.spacing_deg,
                                     modulo ? "--spacing (a modulo table spans 360 deg)"
                                            : "--table-range " + letter + " / --spacing");
  const std::size_t n = t.nominal_deg.size(),
                    max_points = o.max_cross_points ? o.max_cross_points : 200;
  if (n > max_points)
    throw InvalidArgument("--tables: a SINUMERIK CEC table holds at most " +
                          std::to_string(max_points) +
                          " interpolation points (MD18342 $MN_MM_CEC_MAX_POINTS as configured; "
                          "--max-cross-points); the " +
                          letter + " tables every " + export_detail::fixed(o.spacing_deg, 3) +
                          " deg have " + std::to_string(n) + ": use a larger --spacing");
  const AngleMapTerms largest = largest_terms(f);
  std::vector<std::string> outputs;
  std::ostringstream tables;
  const int first = next_table;
  for (int j = 0; j < 3; ++j) {
    if (largest[j] == 0.0) continue;
    const char out_letter = "XYZ"[j];
    const std::string out_name = axis_name(out_letter, o);
    const auto value = [&](double x) { return f.evaluate(x / kRadToDeg)[j]; };
    std::vector<double>& v = t.value_mm[out_letter];
    for (const double x : t.nominal_deg) v.push_back(std::round(value(x) * 1e9) * 1e-9);
    t.max_interpolation_error_mm =
        std::max(t.max_interpolation_error_mm,
                 worst_interpolation_error(t.nominal_deg, v, value, o.samples_between));
    const std::string k = std::to_string(next_table++);
    for (std::size_t i = 0; i < n; ++i)
      tables << "$AN_CEC[" << k << "," << i << "]=" << export_detail::fixed(v[i], 9) << "\n";
    tables << "$AN_CEC_INPUT_AXIS[" << k << "]=(" << name << ")\n"
           << "$AN_CEC_OUTPUT_AXIS[" << k << "]=(" << out_name << ")\n"
           << "$AN_CEC_STEP[" << k << "]=" << export_detail::fixed(o.spacing_deg, 6) << "\n"
           << "$AN_CEC_MIN[" << k << "]=" << export_detail::fixed(lo, 6) << "\n"
           << "$AN_CEC_MAX[" << k << "]=" << export_detail::fixed(hi, 6) << "\n"
           << "$AN_CEC_DIRECTION[" << k << "]=0\n"
           << "$AN_CEC_MULT_BY_TABLE[" << k << "]=0\n"
           << "$AN_CEC_IS_MODULO[" << k << "]=" << (modulo ? 1 : 0) << "\n";
    outputs.push_back(std::string(1, out_letter) + " (" + out_name + ", table " + k + ")");
  }
  std::array<double, 2> tilt_range{0.0, 0.0};
  const double remains = tilt_remains_mm(f, m, o, t.nominal_deg, tilt_range);
  const std::string tilt(1, remains > 0.0 ? m.description().axis(m.tilt_index()).name : '-');
  const std::string over = export_detail::fixed(tilt_range[0], 3) + ".." +
                           export_detail::fixed(tilt_range[1], 3) + " deg";
  const double err = t.max_interpolation_error_mm;
  export_detail::Writer w(CommentDialect::siemens);
  w.line("rotacal export: SINUMERIK cross error compensation (CEC) of the translations of axis " +
         letter + " (input axis " + name + "), values in mm; outputs " + joined(outputs, "none"));
  w.line("holds: E_X" + letter + ", E_Y" + letter + ", E_Z" + letter + " (the translation of " +
         letter + "'s frame at its nominal point) from " +
         joined(t.holds, "no named term of the model"));
  w.line(
      "sign: value = the translation E of the table point at the input axis position, added to "
      "the output axis' position: the tool follows the point (K3: a table's value is added to "
      "its output axis)");
  w.line("points: " + std::to_string(n) + " every " + export_detail::fixed(o.spacing_deg, 6) +
         " deg over " + export_detail::fixed(lo, 6) + ".." + export_detail::fixed(hi, 6) + " deg" +
         (modulo ? ", modulo (the table repeats every turn)"
                 : "; beyond them the end values hold: correction stops there") +
         "; MD18342 $MN_MM_CEC_MAX_POINTS[t] must be >= " + std::to_string(n) + " for tables " +
         std::to_string(first) + ".." + std::to_string(next_table - 1) +
         "; enable with MD32710 CEC_ENABLE of the output axes and SD41300 CEC_TABLE_ENABLE[t]");
  w.line("worst interpolation error between points: " + rounded_up(err) + " mm (" +
         rounded_up(err * 1e3) + " um; the model evaluated at " +
         std::to_string(o.samples_between) + " angles inside each interval, values as written)");
  if (remains > 0.0) {
    const std::string left = export_detail::fixed(remains * 1e3, 3) + " um";
    w.line("held at " + tilt + " = 0 only: at tilt " + tilt + " the translation of " + letter +
           " turns with " + tilt +
           ", and no table multiplication ($AN_CEC_MULT_BY_TABLE) is written; over " + tilt + " " +
           over + " up to " + left + " remains, left to rotacal compensate");
    not_held.push_back("E_X" + letter + ", E_Y" + letter + ", E_Z" + letter + " away from " + tilt +
                       " = 0: up to " + left + " over " + tilt + " " + over +
                       " (the CEC tables hold them at " + tilt + " = 0)");
  }
  for (const std::string& note : f.notes) w.line("left out: " + note);
  w.line("model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path) +
         (in.source.empty() ? "" : "; identified from " + in.source));
  w.line("written: " + (o.generated_at.empty() ? table_written_at() : o.generated_at));
  t.text = "%_N_NC_CEC_INI\nCHANDATA(1)\n" + w.out.str() + tables.str() + "M17\n";
  t.summary = "axis " + letter + " translations (CEC tables " + std::to_string(first) + ".." +
              std::to_string(next_table - 1) + ", input " + name + "), " + std::to_string(n) +
              " points over " + export_detail::fixed(lo, 3) + ".." + export_detail::fixed(hi, 3) +
              " deg" + (modulo ? " modulo" : "") + ", worst interpolation error " +
              rounded_up(err * 1e3) + " um" +
              (remains > 0.0 ? ", at " + tilt + " = 0 only" : std::string());
  return t;
}

}  // namespace sinumerik_table_detail

CompensationTables sinumerik_eec_tables(const ModelFile& model,
                                        const std::vector<AxisErrorFunction>& functions,
                                        const CompensationTableOptions& o) {
  return table_detail::positioning_tables(model, functions, o, "SINUMERIK", "an EEC table",
                                          sinumerik_table_detail::one_table);
}

CompensationTables sinumerik_tables(const ModelFile& model,
                                    const std::vector<AxisErrorFunction>& functions,
                                    const CompensationTableOptions& o) {
  using namespace sinumerik_table_detail;
  const ExportInput in = export_input(model, o.model_path);
  int next_table = 0;
  std::vector<std::string> tilted;
  CompensationTables out = axis_tables(
      model, functions, "SINUMERIK", "an EEC or CEC table", true, [&](const AxisErrorFunction& f) {
        std::vector<CompensationTable> t;
        const AngleMapTerms largest = largest_terms(f);
        if (largest[6] != 0.0) t.push_back(one_table(f, model.machine, o, in));
        if (largest.head<3>().maxCoeff() > 0.0)
          t.push_back(cec_file(f, model.machine, o, in, next_table, tilted));
        return t;
      });
  out.not_held.insert(out.not_held.end(), tilted.begin(), tilted.end());
  return out;
}

}  // namespace rotacal
