// SPDX-License-Identifier: BSD-3-Clause
// The LinuxCNC export of the head machines: the HAL pin of maxkins (a B head over a C table) and
// of 5axiskins (a B/C head), and, for the table's C line, the X/Y joints' HOME_OFFSET.
#include "shared.hpp"

namespace rotacal::export_detail {

std::string linuxcnc_head_kinematics(MachineType m) {
  if (m == parse_machine_type("B-head-C-table")) return "maxkins";
  if (m == parse_machine_type("BC-head")) return "5axiskins";
  return "";
}

// LinuxCNC 2.9 (maxkins.c, 5axiskins.c): the joints J are the tool point at B = 0, the pivot
// (the B line) at J + (0, 0, pivot-length), and the tool point at the pivot plus
// R(B) (0, 0, -pivot-length), B turning about -Y. maxkins turns the table about -Z (world =
// Rz(C) machine) with its C line at joint X = Y = 0; 5axiskins turns the head about +Z with its
// C line through the pivot. So pivot-length is the B line to the tool point: rotacal's
// pivot_length + tool_length plus E_Z0B (the B line's height above the controlled point). No
// other error has a pin: the tool's offset from the B line (E_X0B), the head C line's offset,
// and every orientation are NOT HELD. The table's C line is held by moving the joints' origin.
ControllerExport export_linuxcnc_head(const ExportInput& in, const ExportOptions& o) {
  const std::string kins = linuxcnc_head_kinematics(in.machine);
  const bool table_c = kins == "maxkins";
  const LineMaps L = line_maps(in.machine);
  const MachineDescription& d = in.machine.description();
  const double length = d.pivot_length + d.tool_length;
  ControllerExport ex = new_export(Controller::linuxcnc, kins, "HAL", o);
  std::vector<Param> ps = {{kins + ".pivot-length", "mm", L.tilt_point.row(2)}};
  if (table_c) {  // joint' = joint - C line: HOME_OFFSET' = HOME_OFFSET - E_X0C (E_Y0C)
    ps.push_back({"[JOINT_0]HOME_OFFSET", "mm", -L.c_point.row(0)});
    ps.push_back({"[JOINT_1]HOME_OFFSET", "mm", -L.c_point.row(1)});
  }
  for (std::size_t i = 0; i < ps.size(); ++i)
    ex.values.push_back(value_of(ps[i], current_of(o, ps[i].name, i == 0 ? length : 0.0), in));
  const std::string later =
      " in LinuxCNC 2.9's " + kins +
      ": rotacal compensate --model, or the real-time kinematics (--controller realtime, "
      "docs/linuxcnc_kins.md)";
  const std::string no_orient = "no orientation terms" + later;
  const std::string c_line = table_c ? "[JOINT_0]HOME_OFFSET (the C line at joint X = 0)"
                                     : "no offset of the head's C line from the spindle" + later;
  dispositions(ex, in,
               {c_line,
                table_c ? "[JOINT_1]HOME_OFFSET (the C line at joint Y = 0)"
                        : "no offset of the head's C line from the spindle" + later,
                no_orient, no_orient, "no offset of the tool from the B line" + later,
                kins + ".pivot-length (the B line to the tool point)", no_orient, no_orient},
               {table_c, table_c, false, false, false, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "LinuxCNC 2.9 " + kins + " HAL pin (src/emc/kinematics/" + kins +
             ".c), linear units mm ([TRAJ]LINEAR_UNITS)");
  if (!o.current_given || o.current.count(ex.values[0].name) == 0)
    w.line("current " + ex.values[0].name + ": not given, taken as the description's " +
           "pivot_length + tool_length");
  w.line(std::string("angles: ") +
         (table_c ? "maxkins turns B about -Y and the C table about -Z"
                  : "5axiskins turns C about +Z and B about -Y") +
         "; a B (C) axis of rotacal's machine along +Y (+Z) is LinuxCNC's angle negated. The "
         "positions it holds do not depend on the sense.");
  w.line(kins + ".pivot-length is the B line to the tool point: rotacal's pivot_length + " +
         "tool_length (" + fixed(length, 6) + " mm with the session's tool) plus E_Z0B. For " +
         "another tool add the tool-length difference (LinuxCNC's sample configs sum the " +
         "mechanical pivot and motion.tooloffset.z with sum2).");
  if (table_c) {
    w.line(
        "Put into the machine's INI file (the joints' origin on the C line; rotacal's X, Y are "
        "the joints' X, Y):");
    for (std::size_t i = 1; i < ex.values.size(); ++i)
      w.line(ex.values[i].name + " = " + fixed(ex.values[i].corrected, 6));
  }
  if (ex.not_held.v.cwiseAbs().maxCoeff() > 0)
    w.line("NOT HELD by " + kins + ": " + later.substr(later.find(':') + 2));
  w.out << "setp " << ex.values[0].name << " " << fixed(ex.values[0].corrected, 6) << "\n";
  ex.text = w.out.str();
  return ex;
}

}  // namespace rotacal::export_detail
