// SPDX-License-Identifier: BSD-3-Clause
// LinuxCNC [JOINT_n]COMP_FILE tables of each table axis' positioning error (angle_map.hpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/io/compensation_table.hpp"
#include "rotacal/io/controller_export.hpp"
#include "shared.hpp"
#include "table_shared.hpp"

namespace rotacal {

namespace linuxcnc_table_detail {

using namespace table_detail;

// A file name for the INI lines: printable ASCII without the INI's comment characters, so no
// name becomes a second INI line or a comment.
void check_file_name(const std::string& name) {
  for (const char c : name)
    if (c < 0x20 || c > 0x7e || c == '#' || c == ';')
      throw InvalidArgument("--tables: the table file name '" + name +
                            "' has a character an INI line cannot carry (control, non-ASCII, # "
                            "or ;)");
  if (name.empty()) throw InvalidArgument("--tables: an empty table file name");
}

CompensationTable one_table(const AxisErrorFunction& f, const MachineType& m,
                            const CompensationTableOptions& o, const ExportInput& in) {
  const RotaryAxis& ax = m.description().axis(f.chain_index);
  const auto [lo, asked_hi] = range_of(ax, o);
  // Up to the first point at or past the asked end, so the table covers the whole range.
  const double hi = o.spacing_deg > 0.0 && asked_hi > lo
                        ? lo + std::ceil((asked_hi - lo) / o.spacing_deg - 1e-9) * o.spacing_deg
                        : asked_hi;
  const std::string letter(1, f.axis);
  CompensationTable t;
  t.axis = f.axis;
  t.holds = positioning_sources(f, ax);
  t.joint = f.chain_index == m.rot_index() ? 4 : 3;
  const auto fn = o.file_names.find(f.axis);
  t.file_name = fn != o.file_names.end() ? fn->second : "comp_" + letter + ".txt";
  check_file_name(t.file_name);
  t.nominal_deg =
      equally_spaced_deg(lo, hi, o.spacing_deg, "--table-range " + letter + " / --spacing");
  const std::size_t max_points = o.max_points ? o.max_points : 256;
  if (t.nominal_deg.size() > max_points)
    throw InvalidArgument(
        "--tables: LinuxCNC holds at most " + std::to_string(max_points) +
        " compensation triplets per joint (EMCMOT_COMP_SIZE, src/emc/motion/motion.h); the " +
        letter + " table over " + export_detail::fixed(lo, 3) + ".." + export_detail::fixed(hi, 3) +
        " deg every " + export_detail::fixed(o.spacing_deg, 3) + " deg has " +
        std::to_string(t.nominal_deg.size()) +
        ": use a larger --spacing or a shorter --table-range");
  for (const double p : t.nominal_deg) t.value_deg.push_back(trim_deg(f, p));
  t.max_interpolation_error_deg = worst_interpolation_error(
      t.nominal_deg, t.value_deg, [&](double p) { return trim_deg(f, p); }, o.samples_between);
  std::ostringstream out;
  for (std::size_t i = 0; i < t.nominal_deg.size(); ++i)
    out << export_detail::fixed(t.nominal_deg[i], 6) << " "
        << export_detail::fixed(t.value_deg[i], 9) << " " << export_detail::fixed(t.value_deg[i], 9)
        << "\n";
  // The header follows the numbers: LinuxCNC reads up to the first line that is not three
  // numbers, so these lines (each starting with #) are never read as data.
  export_detail::Writer w(CommentDialect::hash);
  const double err = t.max_interpolation_error_deg;
  w.line("rotacal export: LinuxCNC [JOINT_" + std::to_string(t.joint) + "]COMP_FILE of axis " +
         letter + ", COMP_FILE_TYPE = 1: nominal (deg), trim moving up, trim moving down (deg)");
  w.line("holds: positioning_" + letter + " (actual - commanded angle) from " +
         joined(positioning_sources(f, ax), "no term of the model") + "; the same trim both ways");
  w.line(
      "sign: trim = nominal - actual: LinuxCNC adds it to the motor command, so the axis "
      "reaches the nominal angle (trim = -positioning at the motor angle that reaches it)");
  w.line("points: " + std::to_string(t.nominal_deg.size()) + " every " +
         export_detail::fixed(o.spacing_deg, 6) + " deg over " + export_detail::fixed(lo, 6) +
         ".." + export_detail::fixed(hi, 6) + " deg (LinuxCNC holds at most " +
         std::to_string(max_points) + ")");
  w.line("worst interpolation error between points: " + rounded_up(err) + " deg (" +
         rounded_up(err / kRadToDeg * 1e6) + " urad; the model evaluated at " +
         std::to_string(o.samples_between) + " angles inside each interval)");
  w.line("correction stops outside " + export_detail::fixed(lo, 6) + ".." +
         export_detail::fixed(hi, 6) +
         " deg: LinuxCNC looks the table up on the joint position without modulo and holds the "
         "end values beyond it");
  w.line("BACKLASH of this joint is not used while COMP_FILE is set");
  for (const std::string& n : f.notes) w.line("left out: " + n);
  w.line("model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path) +
         (in.source.empty() ? "" : "; identified from " + in.source));
  w.line("written: " + (o.generated_at.empty() ? table_written_at() : o.generated_at));
  t.text = out.str() + w.out.str();
  t.summary = "axis " + letter + " positioning, joint " + std::to_string(t.joint) + ", " +
              std::to_string(t.nominal_deg.size()) + " points over " + export_detail::fixed(lo, 3) +
              ".." + export_detail::fixed(hi, 3) + " deg, worst interpolation error " +
              export_detail::fixed(err / kRadToDeg * 1e6, 4) + " urad";
  return t;
}

}  // namespace linuxcnc_table_detail

CompensationTables linuxcnc_comp_tables(const ModelFile& model,
                                        const std::vector<AxisErrorFunction>& functions,
                                        const CompensationTableOptions& o) {
  using namespace linuxcnc_table_detail;
  using namespace table_detail;
  const ExportInput in = export_input(model, o.model_path);
  CompensationTables out = positioning_tables(
      model, functions, "linuxcnc", "a LinuxCNC COMP_FILE",
      [&](const AxisErrorFunction& f) { return one_table(f, model.machine, o, in); });
  std::ostringstream ini;
  for (const CompensationTable& t : out.tables)
    ini << "[JOINT_" << t.joint << "]\n"
        << "# axis " << t.axis << " positioning (rotacal export --tables); BACKLASH is not used "
        << "while COMP_FILE is set\n"
        << "COMP_FILE = " << t.file_name << "\nCOMP_FILE_TYPE = 1\n";
  out.ini = ini.str();
  return out;
}

}  // namespace rotacal
