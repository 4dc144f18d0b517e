// SPDX-License-Identifier: BSD-3-Clause
// The SINUMERIK export: the orientable toolholder $TC_CARR, kinematic type P.
#include "shared.hpp"

namespace rotacal::export_detail {

// Orientable toolholder, kinematic type P (W1 function manual): a table point q lands at
// l2 + R(v1, a1)(l3 + R(v2, a2)(l4 + q)), rotations right-handed about v1, v2. So the v1 line
// passes through l2, the v2 line (a1 = 0) through l2 + l3, and l2 + l3 + l4 is the table
// reference. The corrected lines keep that reference: l2' = l2 + dp_tilt, l3' = l3 + dp_C -
// dp_tilt, l4' = l4 - dp_C; v1, v2 carry the tilts (no fine offsets exist for them).
ControllerExport export_siemens(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  const std::string k = "[" + std::to_string(o.toolholder) + "]";
  auto name = [&](int n) { return "$TC_CARR" + std::to_string(n) + k; };
  ControllerExport ex = new_export(Controller::siemens, "$TC_CARR" + k + " type P", "MPF", o);
  const char xyz[] = "xyz";
  auto vector_params = [&](int first, const Map3& coef, const std::string& what) {
    for (int c = 0; c < 3; ++c) {
      Param p{name(first + c), "mm", coef.row(c)};
      ControllerValue v = value_of(p, current_of(o, p.name), in);
      v.name += " (" + what + " " + xyz[c] + ")";
      ex.values.push_back(v);
    }
  };
  vector_params(4, L.tilt_point, "l2");
  vector_params(15, L.c_point - L.tilt_point, "l3");
  vector_params(18, -L.c_point, "l4");
  auto current_vec = [&](int first) {
    return Eigen::Vector3d(current_of(o, name(first)), current_of(o, name(first + 1)),
                           current_of(o, name(first + 2)));
  };
  const AxisVector v1 = corrected_axis(current_vec(7), L.tilt_axis, L.tilt_dir, in,
                                       name(7) + ".." + name(9) + " (v1)");
  const AxisVector v2 =
      corrected_axis(current_vec(10), L.c_axis, L.c_dir, in, name(10) + ".." + name(12) + " (v2)");
  for (int c = 0; c < 3; ++c)
    ex.values.push_back(
        vector_component(name(7 + c) + " (v1 " + xyz[c] + ")", v1, c, in, L.tilt_dir));
  for (int c = 0; c < 3; ++c)
    ex.values.push_back(
        vector_component(name(10 + c) + " (v2 " + xyz[c] + ")", v2, c, in, L.c_dir));
  const std::string t(1, L.tilt);
  dispositions(
      ex, in,
      {"l2, l3 (" + t + " line through l2)", "l2, l3 (" + t + " line through l2)",
       "v1 (" + t + " direction)", "v1 (" + t + " direction)", "l3, l4 (C line through l2 + l3)",
       "l3, l4 (C line through l2 + l3)", "v2 (C direction)", "v2 (C direction)"},
      {true, true, true, true, true, true, true, true});
  Writer w(CommentDialect::siemens);
  header(w, ex, in, o,
         "SINUMERIK orientable toolholder " + ex.kinematics +
             " (W1 function manual: type P, chain l2 v1 l3 v2 l4), "
             "basic values in mm, axis vectors as unit vectors; fine offsets ($TC_CARR41..65) are "
             "not changed");
  w.out << name(23) << "=\"P\"\n";
  for (const ControllerValue& v : ex.values) {
    const std::string bare = v.name.substr(0, v.name.find(' '));
    w.out << bare << "=" << fixed(v.corrected, v.unit == "1" ? 9 : 6) << "\n";
  }
  w.out << "M17\n";
  ex.text = w.out.str();
  return ex;
}

}  // namespace rotacal::export_detail
