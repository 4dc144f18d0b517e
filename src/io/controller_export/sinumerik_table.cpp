// SPDX-License-Identifier: BSD-3-Clause
// SINUMERIK encoder / leadscrew error compensation ($AA_ENC_COMP) of each table axis'
// positioning error (angle_map.hpp).
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
  // An endless axis without a range: a modulo table over one turn (K3: 0 to 360 deg).
  const bool modulo = !ax.limits_deg && !o.range_deg.count(f.axis);
  const auto [lo, asked_hi] = modulo ? std::array<double, 2>{0.0, 360.0} : range_of(ax, o);
  const double hi = !modulo && o.spacing_deg > 0.0 && asked_hi > lo
                        ? lo + std::ceil((asked_hi - lo) / o.spacing_deg - 1e-9) * o.spacing_deg
                        : asked_hi;
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

}  // namespace sinumerik_table_detail

CompensationTables sinumerik_eec_tables(const ModelFile& model,
                                        const std::vector<AxisErrorFunction>& functions,
                                        const CompensationTableOptions& o) {
  using namespace sinumerik_table_detail;
  const ExportInput in = export_input(model, o.model_path);
  return positioning_tables(
      model, functions, "SINUMERIK", "an EEC table",
      [&](const AxisErrorFunction& f) { return one_table(f, model.machine, o, in); });
}

}  // namespace rotacal
