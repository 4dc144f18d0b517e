// SPDX-License-Identifier: BSD-3-Clause
// The ISG/Beckhoff export: the universal kinematic (ID 91).
#include "shared.hpp"

namespace rotacal::export_detail {

// Universal kinematic (ID 91): each axis has a point on its line (0.1 um) and an orientation;
// the chain runs from the workpiece (C, tilt, X, Y, Z) and the orientation of a workpiece-side
// axis is its direction times -1 (a table turning right-handed about n moves the tool about -n).
ControllerExport export_isg(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  ControllerExport ex = new_export(
      Controller::isg, "universal kinematic (ID 91), chain C " + std::string(1, L.tilt) + " X Y Z",
      "channel parameter list", o);
  struct Axis {
    int index;
    const Map3* point;
    const Map3* dir;
    Eigen::Vector3d nominal;
  };
  const Axis axes[2] = {{0, &L.c_point, &L.c_dir, L.c_axis},
                        {1, &L.tilt_point, &L.tilt_dir, L.tilt_axis}};
  for (const Axis& a : axes) {
    const std::string base = "trafo[0].axis[" + std::to_string(a.index) + "]";
    for (int c = 0; c < 3; ++c) {
      Param p{base + ".point[" + std::to_string(c) + "]", "0.1 um", a.point->row(c), 1e4};
      ex.values.push_back(value_of(p, current_of(o, p.name), in));
    }
    Eigen::Vector3d cur;
    for (int c = 0; c < 3; ++c)
      cur[c] = current_of(o, base + ".orientation[" + std::to_string(c) + "]");
    const AxisVector v =
        corrected_axis(cur, a.nominal, *a.dir, in, base + ".orientation", /*default_sense=*/-1.0);
    for (int c = 0; c < 3; ++c) {
      ControllerValue cv =
          vector_component(base + ".orientation[" + std::to_string(c) + "]", v, c, in, *a.dir);
      ex.values.push_back(cv);
    }
  }
  const std::string t(1, L.tilt);
  dispositions(ex, in,
               {"axis[1].point", "axis[1].point", "axis[1].orientation", "axis[1].orientation",
                "axis[0].point", "axis[0].point", "axis[0].orientation", "axis[0].orientation"},
               {true, true, true, true, true, true, true, true});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "ISG/Beckhoff " + ex.kinematics +
             " (P-CHAN-00290..00293), points in 0.1 um, orientations "
             "as unit vectors, workpiece-side orientations negated");
  for (const ControllerValue& v : ex.values)
    w.out << v.name << "  " << fixed(v.corrected, v.unit == "1" ? 9 : 1) << "\n";
  ex.text = w.out.str();
  return ex;
}

}  // namespace rotacal::export_detail
