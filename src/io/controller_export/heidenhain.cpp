// SPDX-License-Identifier: BSD-3-Clause
// The HEIDENHAIN export (mapping only): the Trans rows of the TNC kinematics table.
#include "shared.hpp"

namespace rotacal::export_detail {

// ---------------------------------------------------------------------------- mapping only
// HEIDENHAIN and FANUC do not publish their kinematic formulas: the export is the mapping of
// each error to the rows/parameters that hold it, as line-position changes in machine axes.
ControllerExport export_heidenhain(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  const std::string t(1, L.tilt);
  ControllerExport ex = new_export(
      Controller::heidenhain,
      "kinematics table (Trans rows before MachAxis " + t + " and MachAxis C)", "mapping", o);
  const int a0 =
      in.machine == MachineType::AC_trt ? 1 : 0;  // the tilt line's two position coordinates
  const char xyz[] = "XYZ";
  std::vector<Param> ps = {
      {"Trans " + std::string(1, xyz[a0]) + " before MachAxis " + t, "mm", L.tilt_point.row(a0)},
      {"Trans Z before MachAxis " + t, "mm", L.tilt_point.row(2)},
      {"Trans X before MachAxis C", "mm", L.c_point.row(0)},
      {"Trans Y before MachAxis C", "mm", L.c_point.row(1)},
  };
  for (const Param& p : ps) ex.values.push_back(value_of(p, current_of(o, p.name), in));
  const std::string comp =
      "needs KinematicsComp (ISO 230 errors in .COM files); KinematicsOpt adjusts positions only";
  dispositions(ex, in, {ps[0].name, ps[1].name, comp, comp, ps[2].name, ps[3].name, comp, comp},
               {true, true, false, false, true, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "HEIDENHAIN TNC kinematics table, MAPPING ONLY: the TNC's formulas are not public. The "
         "values are "
         "the rotary-axis line positions in machine coordinates (mm); check the sign of the Trans "
         "rows of "
         "your table (iTNC 530 technical manual, kinematics description) before entering them.");
  ex.text = w.out.str();
  return ex;
}

}  // namespace rotacal::export_detail
