// Location errors into controllers' kinematic parameters: LinuxCNC, Siemens, ISG, HEIDENHAIN, FANUC.
#include "rotacal/io/controller_export.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/core/json_text.hpp"
#include "rotacal/io/controller_comment.hpp"

namespace rotacal {

namespace {

using Row = Eigen::Matrix<double, 1, 8>;
using Map3 = Eigen::Matrix<double, 3, 8>;  // a 3-vector as a linear function of the 8 errors

// The line offsets of ../shared/spec/formats.md as linear maps of the error vector: the tilt
// axis (A or B) and C, their point offsets dp and direction offsets dn. The lines are linear in
// the errors, so each column is the one definition (kinematics/machine.hpp) at a unit error.
struct LineMaps {
  Map3 tilt_point = Map3::Zero(), tilt_dir = Map3::Zero(), c_point = Map3::Zero(), c_dir = Map3::Zero();
  Eigen::Vector3d tilt_axis, c_axis;
  char tilt = 'A';
};

LineMaps line_maps(MachineType m) {
  LineMaps L;
  L.tilt = m == MachineType::AC_trt ? 'A' : 'B';
  const LocationErrors<double> none;
  const AxisLine<double> T0 = tilt_axis_line(m, none), C0 = c_axis_line(m, none);
  L.tilt_axis = T0.direction;
  L.c_axis = C0.direction;
  for (int i = 0; i < 8; ++i) {
    LocationErrors<double> unit;
    unit.v[i] = 1.0;
    const AxisLine<double> T = tilt_axis_line(m, unit), C = c_axis_line(m, unit);
    L.tilt_point.col(i) = T.point - T0.point;
    L.tilt_dir.col(i) = T.direction - T0.direction;
    L.c_point.col(i) = C.point - C0.point;
    L.c_dir.col(i) = C.direction - C0.direction;
  }
  return L;
}

// One parameter: its current value plus scale * (coefficients . errors).
struct Param {
  std::string name, unit;
  Row coef = Row::Zero();
  double scale = 1.0;
  bool written = true;
};

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // no "-0.000"
  return s;
}

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// "E_Y0A - E_Y0C" from a coefficient row.
std::string from_text(const Row& c, MachineType m) {
  const auto& names = location_error_names(m);
  std::string s;
  for (int i = 0; i < 8; ++i) {
    if (c[i] == 0.0) continue;
    const std::string sign = c[i] > 0 ? (s.empty() ? "" : " + ") : (s.empty() ? "-" : " - ");
    s += sign + (std::abs(c[i]) == 1.0 ? "" : fixed(std::abs(c[i]), 3) + " ") + names[static_cast<std::size_t>(i)];
  }
  return s;
}

double current_of(const ExportOptions& o, const std::string& name, double fallback = 0.0) {
  const auto it = o.current.find(name);
  return it == o.current.end() ? fallback : it->second;
}

// The errors as used: an unobservable one is not applied (its parameters keep their value).
Eigen::Matrix<double, 8, 1> applied(const ExportInput& in) {
  Eigen::Matrix<double, 8, 1> e = in.errors.v;
  for (int i = 0; i < 8; ++i)
    if (!in.observable[static_cast<std::size_t>(i)]) e[i] = 0.0;
  return e;
}

ControllerValue value_of(const Param& p, double current, const ExportInput& in) {
  Row c = p.coef;
  for (int i = 0; i < 8; ++i)
    if (!in.observable[static_cast<std::size_t>(i)]) c[i] = 0.0;
  ControllerValue v;
  v.name = p.name;
  v.unit = p.unit;
  v.current = current;
  v.corrected = current + p.scale * (c * applied(in))(0, 0);
  v.std = std::abs(p.scale) * std::sqrt(std::max(0.0, (c * in.covariance * c.transpose())(0, 0)));
  v.from = from_text(p.coef, in.machine);
  return v;
}

// A unit axis vector corrected by a small direction offset: normalize(u + s dn), where u is
// the current vector (or the nominal axis) and s = +-1 its sense against the nominal axis
// (formats.md: for a negated direction the offset is negated too).
struct AxisVector {
  Eigen::Vector3d corrected;
  Eigen::Vector3d current;
  Map3 coef;  // first-order d corrected / d errors
};

AxisVector corrected_axis(const Eigen::Vector3d& current_raw, const Eigen::Vector3d& nominal, const Map3& dn,
                          const ExportInput& in, const std::string& what, double default_sense = 1.0) {
  AxisVector a;
  a.current = current_raw.norm() > 0 ? current_raw : Eigen::Vector3d(default_sense * nominal);
  const Eigen::Vector3d u = a.current.normalized();
  const double cosine = u.dot(nominal);
  if (std::abs(cosine) < std::cos(1.0 * M_PI / 180.0))
    throw InvalidArgument(what + ": the current axis vector (" + fixed(a.current.x(), 6) + ", " + fixed(a.current.y(), 6) +
                          ", " + fixed(a.current.z(), 6) + ") is more than 1 deg from the machine's nominal axis; "
                          "the export corrects a kinematics of this machine");
  const double s = cosine > 0 ? 1.0 : -1.0;
  Map3 c = s * dn;
  for (int i = 0; i < 8; ++i)
    if (!in.observable[static_cast<std::size_t>(i)]) c.col(i).setZero();
  a.coef = c;
  a.corrected = (u + c * in.errors.v).normalized();
  return a;
}

ControllerValue vector_component(const std::string& name, const AxisVector& a, int k, const ExportInput& in,
                                 const Map3& dn) {
  ControllerValue v;
  v.name = name;
  v.unit = "1";
  v.current = a.current[k];
  v.corrected = a.corrected[k];
  const Row c = a.coef.row(k);
  v.std = std::sqrt(std::max(0.0, (c * in.covariance * c.transpose())(0, 0)));
  v.from = from_text(dn.row(k), in.machine);
  return v;
}

// The file: comment lines through the dialect's comment writer (a model path, a session or
// a date may hold any text), then the values.
struct Writer {
  explicit Writer(CommentDialect d) : dialect(d) {}
  CommentDialect dialect;
  std::ostringstream out;
  void line(const std::string& s = "") {
    for (const std::string& l : comment_lines(dialect, s)) out << l << "\n";
  }
};

ControllerExport new_export(Controller c, const std::string& kinematics, const std::string& file_kind,
                            const ExportOptions& o) {
  ControllerExport ex;
  ex.controller = c;
  ex.kinematics = kinematics;
  ex.file_kind = file_kind;
  ex.current_given = o.current_given;
  return ex;
}

void header(Writer& w, const ControllerExport& ex, const ExportInput& in, const ExportOptions& o,
            const std::string& title) {
  w.line("rotacal export: " + title);
  w.line("model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path) +
         (in.source.empty() ? "" : "; identified from " + in.source));
  w.line("written: " + (o.generated_at.empty() ? utc_now() : o.generated_at));
  w.line(ex.current_given ? "current values: as given (the values active while the test ran)"
                          : "current values: NOT GIVEN - zero offsets assumed, so each value below is the "
                            "correction itself; add it to the controller's value");
  if (!in.full_covariance) w.line("1-sigma: from each error's own std (the model holds no covariance)");
  w.line();
  w.line("parameter | current | corrected | 1-sigma | unit | from");
  for (const ControllerValue& v : ex.values) {
    const int d = v.unit == "1" ? 9 : v.unit == "0.1 um" ? 1 : 6;
    w.line(v.name + " | " + fixed(v.current, d) + " | " + fixed(v.corrected, d) + " | " + fixed(v.std, d + 1) + " | " +
           v.unit + " | " + (v.from.empty() ? "-" : v.from));
  }
  w.line();
  for (std::size_t i = 0; i < ex.errors.size(); ++i) {
    const ErrorDisposition& e = ex.errors[i];
    const bool angle = location_error_is_angle(static_cast<int>(i));
    const std::string val = e.observable ? fixed(e.value * (angle ? 1e6 : 1e3), 2) + " +- " +
                                               fixed(e.std * (angle ? 1e6 : 1e3), 2) + (angle ? " urad" : " um")
                                         : "not determined by the data";
    w.line(e.name + " = " + val + ": " + (e.held ? "held in " : "NOT HELD: ") + e.where);
  }
  if (ex.not_held.v.cwiseAbs().maxCoeff() > 0)
    w.line("Errors not held remain: apply them as NC compensation (rotacal compensate --model ...).");
  w.line();
}

void dispositions(ControllerExport& ex, const ExportInput& in, const std::array<std::string, 8>& where,
                  const std::array<bool, 8>& held) {
  const auto& names = location_error_names(in.machine);
  for (int i = 0; i < 8; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ErrorDisposition d;
    d.name = names[k];
    d.value = in.errors.v[i];
    d.std = std::sqrt(std::max(0.0, in.covariance(i, i)));
    d.observable = in.observable[k];
    d.held = held[k] && d.observable;
    d.where = !d.observable ? "not determined by the data: the parameters keep their current value" : where[k];
    if (!held[k] && d.observable) ex.not_held.v[i] = in.errors.v[i];
    ex.errors.push_back(d);
  }
}

// ---------------------------------------------------------------------------- LinuxCNC
// trtfuncs.c: J = r + d + R_tilt(t)[Rz(C)(P - r) - d], with r the rot-point pins and d =
// (0, y-offset, z-offset + tool-offset) (AC) or (x-offset, 0, z-offset + tool-offset) (BC): the
// C line passes through (x-rot-point, y-rot-point), the tilt line through r + d; both turn
// right-handed (the module's default directions). No orientation terms exist.
ControllerExport export_linuxcnc(const ExportInput& in, const ExportOptions& o) {
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
               {ac ? "y-offset (A line y = y-rot-point + y-offset)" : "x-offset (B line x = x-rot-point + x-offset)",
                "z-offset (" + std::string(1, L.tilt) + " line z = z-rot-point + z-offset)", no_orient, no_orient,
                "x-rot-point (and " + off + ", which is relative to it)",
                ac ? "y-rot-point (and y-offset, which is relative to it)" : "y-rot-point", no_orient, no_orient},
               {true, true, false, false, true, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "LinuxCNC " + kins + " HAL pins (src/emc/kinematics/trtfuncs.c), linear units mm ([TRAJ]LINEAR_UNITS), "
         "angles as the module's default directions (right-handed table rotation)");
  w.line(std::string(ac ? "x-offset" : "y-offset") + " is never read by " + kins + "; tool-offset stays wired to "
         "motion.tooloffset.z.");
  for (const ControllerValue& v : ex.values) w.out << "setp " << v.name << " " << fixed(v.corrected, 6) << "\n";
  ex.text = w.out.str();
  return ex;
}

// ---------------------------------------------------------------------------- Siemens
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
    return Eigen::Vector3d(current_of(o, name(first)), current_of(o, name(first + 1)), current_of(o, name(first + 2)));
  };
  const AxisVector v1 = corrected_axis(current_vec(7), L.tilt_axis, L.tilt_dir, in, name(7) + ".." + name(9) + " (v1)");
  const AxisVector v2 = corrected_axis(current_vec(10), L.c_axis, L.c_dir, in, name(10) + ".." + name(12) + " (v2)");
  for (int c = 0; c < 3; ++c)
    ex.values.push_back(vector_component(name(7 + c) + " (v1 " + xyz[c] + ")", v1, c, in, L.tilt_dir));
  for (int c = 0; c < 3; ++c)
    ex.values.push_back(vector_component(name(10 + c) + " (v2 " + xyz[c] + ")", v2, c, in, L.c_dir));
  const std::string t(1, L.tilt);
  dispositions(ex, in,
               {"l2, l3 (" + t + " line through l2)", "l2, l3 (" + t + " line through l2)", "v1 (" + t + " direction)",
                "v1 (" + t + " direction)", "l3, l4 (C line through l2 + l3)", "l3, l4 (C line through l2 + l3)",
                "v2 (C direction)", "v2 (C direction)"},
               {true, true, true, true, true, true, true, true});
  Writer w(CommentDialect::siemens);
  header(w, ex, in, o,
         "SINUMERIK orientable toolholder " + ex.kinematics + " (W1 function manual: type P, chain l2 v1 l3 v2 l4), "
         "basic values in mm, axis vectors as unit vectors; fine offsets ($TC_CARR41..65) are not changed");
  w.out << name(23) << "=\"P\"\n";
  for (const ControllerValue& v : ex.values) {
    const std::string bare = v.name.substr(0, v.name.find(' '));
    w.out << bare << "=" << fixed(v.corrected, v.unit == "1" ? 9 : 6) << "\n";
  }
  w.out << "M17\n";
  ex.text = w.out.str();
  return ex;
}

// ---------------------------------------------------------------------------- ISG
// Universal kinematic (ID 91): each axis has a point on its line (0.1 um) and an orientation;
// the chain runs from the workpiece (C, tilt, X, Y, Z) and the orientation of a workpiece-side
// axis is its direction times -1 (a table turning right-handed about n moves the tool about -n).
ControllerExport export_isg(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  ControllerExport ex = new_export(Controller::isg, "universal kinematic (ID 91), chain C " + std::string(1, L.tilt) + " X Y Z", "channel parameter list", o);
  struct Axis { int index; const Map3* point; const Map3* dir; Eigen::Vector3d nominal; };
  const Axis axes[2] = {{0, &L.c_point, &L.c_dir, L.c_axis}, {1, &L.tilt_point, &L.tilt_dir, L.tilt_axis}};
  for (const Axis& a : axes) {
    const std::string base = "trafo[0].axis[" + std::to_string(a.index) + "]";
    for (int c = 0; c < 3; ++c) {
      Param p{base + ".point[" + std::to_string(c) + "]", "0.1 um", a.point->row(c), 1e4};
      ex.values.push_back(value_of(p, current_of(o, p.name), in));
    }
    Eigen::Vector3d cur;
    for (int c = 0; c < 3; ++c) cur[c] = current_of(o, base + ".orientation[" + std::to_string(c) + "]");
    const AxisVector v = corrected_axis(cur, a.nominal, *a.dir, in, base + ".orientation", /*default_sense=*/-1.0);
    for (int c = 0; c < 3; ++c) {
      ControllerValue cv = vector_component(base + ".orientation[" + std::to_string(c) + "]", v, c, in, *a.dir);
      ex.values.push_back(cv);
    }
  }
  const std::string t(1, L.tilt);
  dispositions(ex, in,
               {"axis[1].point", "axis[1].point", "axis[1].orientation", "axis[1].orientation", "axis[0].point",
                "axis[0].point", "axis[0].orientation", "axis[0].orientation"},
               {true, true, true, true, true, true, true, true});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "ISG/Beckhoff " + ex.kinematics + " (P-CHAN-00290..00293), points in 0.1 um, orientations "
         "as unit vectors, workpiece-side orientations negated");
  for (const ControllerValue& v : ex.values)
    w.out << v.name << "  " << fixed(v.corrected, v.unit == "1" ? 9 : 1) << "\n";
  ex.text = w.out.str();
  return ex;
}

// ---------------------------------------------------------------------------- mapping only
// HEIDENHAIN and FANUC do not publish their kinematic formulas: the export is the mapping of
// each error to the rows/parameters that hold it, as line-position changes in machine axes.
ControllerExport export_heidenhain(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  const std::string t(1, L.tilt);
  ControllerExport ex = new_export(Controller::heidenhain, "kinematics table (Trans rows before MachAxis " + t + " and MachAxis C)", "mapping", o);
  const int a0 = in.machine == MachineType::AC_trt ? 1 : 0;  // the tilt line's two position coordinates
  const char xyz[] = "XYZ";
  std::vector<Param> ps = {
      {"Trans " + std::string(1, xyz[a0]) + " before MachAxis " + t, "mm", L.tilt_point.row(a0)},
      {"Trans Z before MachAxis " + t, "mm", L.tilt_point.row(2)},
      {"Trans X before MachAxis C", "mm", L.c_point.row(0)},
      {"Trans Y before MachAxis C", "mm", L.c_point.row(1)},
  };
  for (const Param& p : ps) ex.values.push_back(value_of(p, current_of(o, p.name), in));
  const std::string comp = "needs KinematicsComp (ISO 230 errors in .COM files); KinematicsOpt adjusts positions only";
  dispositions(ex, in,
               {ps[0].name, ps[1].name, comp, comp, ps[2].name, ps[3].name, comp, comp},
               {true, true, false, false, true, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "HEIDENHAIN TNC kinematics table, MAPPING ONLY: the TNC's formulas are not public. The values are "
         "the rotary-axis line positions in machine coordinates (mm); check the sign of the Trans rows of "
         "your table (iTNC 530 technical manual, kinematics description) before entering them.");
  ex.text = w.out.str();
  return ex;
}

ControllerExport export_fanuc(const ExportInput& in, const ExportOptions& o) {
  const LineMaps L = line_maps(in.machine);
  ControllerExport ex = new_export(Controller::fanuc, "tool centre point control, two table axes (No. 19680 = 12)", "mapping", o);
  const char xyz[] = "XYZ";
  for (int c = 0; c < 3; ++c) {
    Param p{"No. " + std::to_string(19700 + c) + " (rotary table position " + xyz[c] + ")", "mm", L.tilt_point.row(c)};
    ex.values.push_back(value_of(p, current_of(o, p.name.substr(0, 9)), in));
  }
  for (int c = 0; c < 3; ++c) {
    Param p{"No. " + std::to_string(19703 + c) + " (offset first to second table axis " + xyz[c] + ")", "mm",
            L.c_point.row(c) - L.tilt_point.row(c)};
    ex.values.push_back(value_of(p, current_of(o, p.name.substr(0, 9)), in));
  }
  const std::string none = "no parameter holds an axis tilt (axis directions are chosen among X, Y, Z)";
  dispositions(ex, in,
               {"No. 19700-19702 and 19703-19705", "No. 19700-19702 and 19703-19705", none, none, "No. 19703-19705",
                "No. 19703-19705", none, none},
               {true, true, false, false, true, true, false, false});
  Writer w(CommentDialect::hash);
  header(w, ex, in, o,
         "FANUC 30i tool centre point parameters, MAPPING ONLY: the formulas are not public. No. 19703-19705 are "
         "documented (30i-A manual A-79348E); that 19700-19702 hold the rotary table position is inferred from "
         "the numbering. Axis rotation sense (No. 19684/19689) does not change these positions.");
  ex.text = w.out.str();
  return ex;
}

const std::map<std::string, Controller>& controller_names() {
  static const std::map<std::string, Controller> names = {{"linuxcnc", Controller::linuxcnc},
                                                          {"siemens", Controller::siemens},
                                                          {"isg", Controller::isg},
                                                          {"heidenhain", Controller::heidenhain},
                                                          {"fanuc", Controller::fanuc}};
  return names;
}

}  // namespace

Controller parse_controller(const std::string& name, const std::string& option) {
  const auto it = controller_names().find(name);
  if (it != controller_names().end()) return it->second;
  std::string known;
  for (const auto& [n, c] : controller_names()) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument(option + " '" + name + "': unknown controller (one of " + known + ")");
}

std::string to_string(Controller c) {
  for (const auto& [n, k] : controller_names())
    if (k == c) return n;
  return "?";
}

ExportInput export_input(const ModelFile& model, const std::string& model_path) {
  ExportInput in;
  in.machine = model.machine;
  in.errors = model.location_errors;
  in.observable = model.observable;
  in.model_path = model_path;
  const auto& names = location_error_names(model.machine);
  const nlohmann::ordered_json& doc = model.document;
  for (int i = 0; i < 8; ++i) {
    const auto& e = doc.at("location_errors").at(names[static_cast<std::size_t>(i)]);
    const double s = e.contains("std") && e["std"].is_number() ? e["std"].get<double>() : 0.0;
    in.covariance(i, i) = s * s;
  }
  if (doc.contains("covariance") && doc["covariance"].is_object()) {
    const auto& cov = doc["covariance"];
    const auto& params = cov.at("parameters");
    std::array<int, 8> at{};
    bool all = true;
    for (int i = 0; i < 8; ++i) {
      at[static_cast<std::size_t>(i)] = -1;
      for (std::size_t j = 0; j < params.size(); ++j)
        if (params[j] == names[static_cast<std::size_t>(i)]) at[static_cast<std::size_t>(i)] = static_cast<int>(j);
      all = all && at[static_cast<std::size_t>(i)] >= 0;
    }
    if (all) {
      bool finite = true;
      Eigen::Matrix<double, 8, 8> c;
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j) {
          const auto& x = cov.at("matrix").at(static_cast<std::size_t>(at[static_cast<std::size_t>(i)]))
                              .at(static_cast<std::size_t>(at[static_cast<std::size_t>(j)]));
          finite = finite && x.is_number();
          c(i, j) = x.is_number() ? x.get<double>() : 0.0;
        }
      if (finite) {
        in.covariance = c;
        in.full_covariance = true;
      }
    }
  }
  if (doc.contains("source") && doc["source"].is_object()) {
    const auto& s = doc["source"];
    auto str = [&](const char* k) { return s.contains(k) && s[k].is_string() ? s[k].get<std::string>() : std::string(); };
    in.source = str("session");
    if (!str("identified_at").empty()) in.source += " on " + str("identified_at");
    if (!str("session_sha256").empty()) in.source += " (sha256 " + str("session_sha256").substr(0, 16) + "...)";
  }
  return in;
}

namespace {
// The exports map the two table machines' errors onto their controllers' table kinematics
// (docs/controller_exports.md); other chains have other parameter sets, not written yet.
void require_table_machine(MachineType m) {
  if (m != MachineType::AC_trt && m != MachineType::BC_trt)
    throw InvalidArgument("export: the controller exports are written for the AC-trt and BC-trt tables; a " +
                          to_string(m) + " (" + m.description().configuration() +
                          ") machine's identified errors are in its model file (--save-model)");
}
}  // namespace

ControllerExport export_kinematics(Controller c, const ExportInput& in, const ExportOptions& o) {
  require_table_machine(in.machine);
  if (o.toolholder < 1 || o.toolholder > 99)
    throw InvalidArgument("--toolholder " + std::to_string(o.toolholder) + ": must be 1..99");
  const std::vector<std::string> known = current_parameter_names(c, in.machine, o.toolholder);
  for (const auto& [name, value] : o.current) {
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw InvalidArgument("current value '" + name + "' is not a parameter of the " + to_string(c) + " export");
    if (!std::isfinite(value)) throw InvalidArgument("current value '" + name + "' is not finite");
  }
  switch (c) {
    case Controller::linuxcnc: return export_linuxcnc(in, o);
    case Controller::siemens: return export_siemens(in, o);
    case Controller::isg: return export_isg(in, o);
    case Controller::heidenhain: return export_heidenhain(in, o);
    case Controller::fanuc: return export_fanuc(in, o);
  }
  throw InvalidArgument("export: unknown controller");
}

std::vector<std::string> current_parameter_names(Controller c, MachineType machine, int toolholder) {
  require_table_machine(machine);
  ExportInput in;
  in.machine = machine;
  in.observable.fill(true);
  ExportOptions o;
  o.toolholder = toolholder;
  o.generated_at = "-";
  ControllerExport ex;
  switch (c) {
    case Controller::linuxcnc: ex = export_linuxcnc(in, o); break;
    case Controller::siemens: ex = export_siemens(in, o); break;
    case Controller::isg: ex = export_isg(in, o); break;
    case Controller::heidenhain: ex = export_heidenhain(in, o); break;
    case Controller::fanuc: ex = export_fanuc(in, o); break;
  }
  std::vector<std::string> names;
  for (const ControllerValue& v : ex.values) {
    const std::size_t cut = c == Controller::fanuc ? 9 : c == Controller::siemens ? v.name.find(' ') : std::string::npos;
    names.push_back(v.name.substr(0, cut));
  }
  return names;
}

namespace {
// A controller's offsets and pivots are within a machine's size: a kilometre (or 1e6 deg) is
// no value a controller holds, and 1e308 would be written back as a 309-digit number.
constexpr double kMaxCurrent = 1e6;
const char* const kMaxCurrentText = "1e6";
bool plausible_current(double v) { return std::isfinite(v) && std::abs(v) <= kMaxCurrent; }
}  // namespace

std::map<std::string, double> parse_current_parameters(Controller c, MachineType machine, const std::string& text,
                                                       const std::string& source, int toolholder) {
  const std::vector<std::string> known = current_parameter_names(c, machine, toolholder);
  auto is_known = [&](const std::string& n) { return std::find(known.begin(), known.end(), n) != known.end(); };
  std::map<std::string, double> out;
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') {  // the documented JSON
    const nlohmann::ordered_json j = parse_json(text, source);  // bounded, strict; ParseError names the line
    if (!j.is_object() || !j.contains("parameters") || !j["parameters"].is_object())
      throw InvalidArgument(source + ": expected {\"controller\": ..., \"parameters\": {name: value}}");
    if (j.contains("controller") && j["controller"] != to_string(c))
      throw InvalidArgument(source + ": values of controller " + j["controller"].dump() + ", export for " + to_string(c));
    for (const auto& [name, value] : j["parameters"].items()) {
      if (!is_known(name)) throw InvalidArgument(source + ": parameters." + name + ": not a parameter of this export");
      if (!value.is_number() || !plausible_current(value.get<double>()))
        throw InvalidArgument(source + ": parameters." + name + ": must be a finite number of at most " +
                              kMaxCurrentText + " (mm or deg)");
      out[name] = value.get<double>();
    }
    return out;
  }
  if (c != Controller::linuxcnc && c != Controller::siemens)
    throw InvalidArgument(source + ": current values of " + to_string(c) + " are read from the JSON form only");
  std::istringstream in(text);
  std::string line;
  int n = 0;
  const std::string kins = machine == MachineType::AC_trt ? "xyzac-trt-kins." : "xyzbc-trt-kins.";
  while (std::getline(in, line)) {
    ++n;
    const std::string where = source + ":" + std::to_string(n);
    std::istringstream ls(line.substr(0, line.find(c == Controller::linuxcnc ? '#' : ';')));
    std::string name, value;
    if (c == Controller::linuxcnc) {
      std::string cmd;
      if (!(ls >> cmd) || cmd != "setp" || !(ls >> name) || name.rfind(kins, 0) != 0) continue;
      if (!(ls >> value)) throw InvalidArgument(where + ": setp " + name + " without a value");
      if (name == kins + "tool-offset" || name == kins + "conventional-directions" || name == kins + "x-offset" ||
          name == kins + "y-offset") {
        if (!is_known(name)) continue;  // read by the module but not changed by the export
      }
    } else {
      std::string stmt;
      std::getline(ls, stmt);
      const std::size_t eq = stmt.find('=');
      if (stmt.find("$TC_CARR") == std::string::npos || eq == std::string::npos) continue;
      auto trim = [](std::string s) {
        s.erase(0, s.find_first_not_of(" \t"));
        s.erase(s.find_last_not_of(" \t\r") + 1);
        return s;
      };
      name = trim(stmt.substr(0, eq));
      value = trim(stmt.substr(eq + 1));
      if (name.find("[" + std::to_string(toolholder) + "]") == std::string::npos) continue;  // another data set
      if (!is_known(name)) continue;  // names, type, limits, fine offsets: kept as they are
    }
    if (!is_known(name)) throw InvalidArgument(where + ": " + name + " is not a parameter of this export");
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0' || !plausible_current(v))
      throw InvalidArgument(where + ": " + name + ": '" + value + "' is not a finite number of at most " +
                            kMaxCurrentText + " (mm or deg)");
    out[name] = v;
  }
  if (out.empty()) throw InvalidArgument(source + ": no current values of " + to_string(c) + " found");
  return out;
}

}  // namespace rotacal
