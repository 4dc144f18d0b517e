// SPDX-License-Identifier: BSD-3-Clause
// The LinuxCNC export: the HAL pins of xyzac-trt-kins / xyzbc-trt-kins.
#include "shared.hpp"

namespace rotacal::export_detail {

// trtfuncs.c: J = r + d + R_tilt(t)[Rz(C)(P - r) - d], with r the rot-point pins and d =
// (0, y-offset, z-offset + tool-offset) (AC) or (x-offset, 0, z-offset + tool-offset) (BC): the
// C line passes through (x-rot-point, y-rot-point), the tilt line through r + d; both turn
// right-handed (the module's default directions). No orientation terms exist.
ControllerExport export_linuxcnc(const ExportInput& in, const ExportOptions& o) {
  if (in.machine.has_head()) return export_linuxcnc_head(in, o);
  const LineMaps L = line_maps(in.machine);
  const bool ac = in.machine == MachineType::AC_trt;
  const std::string kins = ac ? "xyzac-trt-kins" : "xyzbc-trt-kins";
  ControllerExport ex = new_export(Controller::linuxcnc, kins, "HAL", o);
  std::vector<Param> ps = {
      {kins + ".x-rot-point", "mm", L.c_point.row(0)},
      {kins + ".y-rot-point", "mm", L.c_point.row(1)},
      {kins + ".z-rot-point", "mm", Row::Zero()},
      ac ? Param{kins + ".y-offset", "mm", L.tilt_point.row(1) - L.c_point.row(1)}
         : Param{kins + ".x-offset", "mm", L.tilt_point.row(0) - L.c_point.row(0)},
      {kins + ".z-offset", "mm", L.tilt_point.row(2)},
  };
  for (const Param& p : ps) ex.values.push_back(value_of(p, current_of(o, p.name), in));
  const std::string off = ac ? "y-offset" : "x-offset";
  const std::string no_orient = "no orientation terms in " + kins + " (trtfuncs.c)";
  dispositions(ex, in,
               {ac ? "y-offset (A line y = y-rot-point + y-offset)"
                   : "x-offset (B line x = x-rot-point + x-offset)",
                "z-offset (" + std::string(1, L.tilt) + " line z = z-rot-point + z-offset)",
                no_orient, no_orient, "x-rot-point (and " + off + ", which is relative to it)",
                ac ? "y-rot-point (and y-offset, which is relative to it)" : "y-rot-point",
                no_orient, no_orient},
               {true, true, false, false, true, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "LinuxCNC " + kins +
             " HAL pins (src/emc/kinematics/trtfuncs.c), linear units mm ([TRAJ]LINEAR_UNITS), "
             "angles as the module's default directions (right-handed table rotation)");
  w.line(std::string(ac ? "x-offset" : "y-offset") + " is never read by " + kins +
         "; tool-offset stays wired to "
         "motion.tooloffset.z.");
  for (const ControllerValue& v : ex.values)
    w.out << "setp " << v.name << " " << fixed(v.corrected, 6) << "\n";
  ex.text = w.out.str();
  return ex;
}

}  // namespace rotacal::export_detail
