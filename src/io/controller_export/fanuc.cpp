// SPDX-License-Identifier: BSD-3-Clause
// The FANUC export (mapping only): the 30i tool centre point parameters 19700-19705. HEIDENHAIN
// and FANUC do not publish their kinematic formulas: the export is the mapping of each error
// to the parameters that hold it, as line-position changes in machine axes.
#include "shared.hpp"

namespace rotacal::export_detail {

ControllerExport export_fanuc(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  ControllerExport ex =
      new_export(Controller::fanuc, "tool centre point control, two table axes (No. 19680 = 12)",
                 "mapping", o);
  const char xyz[] = "XYZ";
  for (int c = 0; c < 3; ++c) {
    Param p{"No. " + std::to_string(19700 + c) + " (rotary table position " + xyz[c] + ")", "mm",
            L.tilt_point.row(c)};
    ex.values.push_back(value_of(p, current_of(o, p.name.substr(0, 9)), in));
  }
  for (int c = 0; c < 3; ++c) {
    Param p{
        "No. " + std::to_string(19703 + c) + " (offset first to second table axis " + xyz[c] + ")",
        "mm", L.c_point.row(c) - L.tilt_point.row(c)};
    ex.values.push_back(value_of(p, current_of(o, p.name.substr(0, 9)), in));
  }
  const std::string none =
      "no parameter holds an axis tilt (axis directions are chosen among X, Y, Z)";
  dispositions(ex, in,
               {"No. 19700-19702 and 19703-19705", "No. 19700-19702 and 19703-19705", none, none,
                "No. 19703-19705", "No. 19703-19705", none, none},
               {true, true, false, false, true, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "FANUC 30i tool centre point parameters, MAPPING ONLY: the formulas are not public. No. "
         "19703-19705 are "
         "documented (30i-A manual A-79348E); that 19700-19702 hold the rotary table position is "
         "inferred from "
         "the numbering. Axis rotation sense (No. 19684/19689) does not change these positions.");
  ex.text = w.out.str();
  return ex;
}

}  // namespace rotacal::export_detail
