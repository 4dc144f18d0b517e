// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/kinematics/machine_description.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "rotacal/core/error.hpp"
#include "rotacal/core/json_text.hpp"

namespace rotacal {

namespace {

using json = nlohmann::ordered_json;

Eigen::Vector3d unit(int k) { return Eigen::Vector3d::Unit(k); }

}  // namespace

RotaryAxis make_rotary_axis(char name, const Eigen::Vector3d& direction,
                            const Eigen::Vector3d& point, bool on_head,
                            std::optional<std::array<double, 2>> limits_deg,
                            const std::string& where) {
  if (!direction.allFinite() || !point.allFinite())
    throw InvalidArgument(where + ": direction and point must be finite numbers");
  const double len =
      direction.stableNorm();  // norm() overflows for [1e200, 1e200, 0]: then 0 after dividing
  if (!(len > 1e-9)) throw InvalidArgument(where + ".direction is zero: an axis needs a direction");
  RotaryAxis a;
  a.name = name;
  a.direction = direction / len;
  a.point = point;
  a.limits_deg = limits_deg;
  a.on_head = on_head;
  const std::string letter(1, name);
  // Principal: A along +-X, B along +-Y, C along +-Z (to 1e-12 after normalising).
  int along = -1;
  for (int k = 0; k < 3; ++k)
    if (std::abs(std::abs(a.direction[k]) - 1.0) < 1e-12) along = k;
  const int letter_index = name == 'A' ? 0 : name == 'B' ? 1 : name == 'C' ? 2 : -1;
  if (along >= 0 && letter_index < 0)
    throw InvalidArgument(
        where + ".name '" + letter + "' is not A, B or C, but the axis lies along " +
        std::string(1, "XYZ"[along]) + " (formats.md: A along X, B along Y, C along Z)");
  if (along >= 0) a.direction = unit(along) * (a.direction[along] > 0 ? 1.0 : -1.0);
  if (along >= 0 && along == letter_index) {
    // formats.md table: A: dp = (0, E_Y0A, E_Z0A), dn = (0, E_C0A, -E_B0A);
    // B: dp = (E_X0B, 0, E_Z0B), dn = (-E_C0B, 0, E_A0B); C: dp = (E_X0C, E_Y0C, 0),
    // dn = (E_B0C, -E_A0C, 0); dn negated with n.
    const int i1 = (along + 1) % 3, i2 = (along + 2) % 3;
    const int p1 = std::min(i1, i2), p2 = std::max(i1, i2);
    a.principal = along;
    a.position_basis.col(0) = unit(p1);
    a.position_basis.col(1) = unit(p2);
    // Orientation errors e2, e3 are tilts about the other two principal axes, in XYZ order:
    // a tilt about axis j by e moves the direction n by e * (e_j x n).
    a.direction_basis.col(0) = unit(p1).cross(unit(along));
    a.direction_basis.col(1) = unit(p2).cross(unit(along));
    const char L[3] = {'X', 'Y', 'Z'}, R[3] = {'A', 'B', 'C'};
    a.error_names = {
        std::string("E_") + L[p1] + "0" + letter, std::string("E_") + L[p2] + "0" + letter,
        std::string("E_") + R[p1] + "0" + letter, std::string("E_") + R[p2] + "0" + letter};
    if (a.direction[along] < 0) a.direction_basis = -a.direction_basis;
    a.radial1 = unit(i1);
    a.radial2 = unit(i2);
    return a;
  }
  // Any other axis: u = unit(e x n) with e the first of X, Y, Z with |e . n| <= 0.5, v = n x u.
  int e = 0;
  while (std::abs(a.direction[e]) > 0.5) ++e;
  const Eigen::Vector3d u = unit(e).cross(a.direction).normalized();
  const Eigen::Vector3d v = a.direction.cross(u);
  a.position_basis << u, v;
  a.direction_basis << u, v;
  a.error_names = {"E_U0" + letter, "E_V0" + letter, "E_DU0" + letter, "E_DV0" + letter};
  a.radial1 = u;
  a.radial2 = v;
  return a;
}

const RotaryAxis& MachineDescription::axis(int k) const {
  const int nt = static_cast<int>(table_axes.size());
  return k < nt ? table_axes[static_cast<std::size_t>(k)]
                : head_axes[static_cast<std::size_t>(k - nt)];
}

std::string MachineDescription::configuration() const {
  return table_axes.size() == 2  ? "table-table"
         : head_axes.size() == 2 ? "head-head"
                                 : "head-table";
}

int MachineDescription::rot_index() const {
  const bool z0 = std::abs(std::abs(axis(0).direction.z()) - 1.0) < 1e-12;
  const bool z1 = std::abs(std::abs(axis(1).direction.z()) - 1.0) < 1e-12;
  if (z0 != z1) return z0 ? 0 : 1;
  // Nearest the tool-workpiece interface: T2 (table-table), the table axis (head-table), H2.
  if (table_axes.size() == 2) return 1;
  if (head_axes.size() == 2) return 1;
  return 0;
}

std::array<std::string, 8> MachineDescription::location_error_names() const {
  std::array<std::string, 8> out;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 4; ++i)
      out[static_cast<std::size_t>(4 * k + i)] = axis(k).error_names[static_cast<std::size_t>(i)];
  return out;
}

bool MachineDescription::same_kinematics(const MachineDescription& o) const {
  auto same_axes = [](const std::vector<RotaryAxis>& a, const std::vector<RotaryAxis>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i].name != b[i].name || a[i].direction != b[i].direction || a[i].point != b[i].point ||
          a[i].limits_deg != b[i].limits_deg)
        return false;
    return true;
  };
  return same_axes(table_axes, o.table_axes) && same_axes(head_axes, o.head_axes) &&
         pivot_length == o.pivot_length && tool_length == o.tool_length &&
         travel_mm.has_value() == o.travel_mm.has_value() &&
         (!travel_mm || *travel_mm == *o.travel_mm);
}

namespace {

double finite_number(const json& v, const std::string& where) {
  if (!v.is_number()) throw InvalidArgument(where + " must be a number, not " + v.dump());
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw InvalidArgument(where + " is not a finite number");
  return x;
}

Eigen::Vector3d vector3(const json& v, const std::string& where) {
  if (!v.is_array() || v.size() != 3)
    throw InvalidArgument(where + " must be an array of 3 numbers");
  return {finite_number(v[0], where + "[0]"), finite_number(v[1], where + "[1]"),
          finite_number(v[2], where + "[2]")};
}

std::array<double, 2> pair(const json& v, const std::string& where) {
  if (!v.is_array() || v.size() != 2) throw InvalidArgument(where + " must be an array [min, max]");
  const std::array<double, 2> p = {finite_number(v[0], where + "[0]"),
                                   finite_number(v[1], where + "[1]")};
  if (!(p[0] < p[1])) throw InvalidArgument(where + " must have min < max");
  return p;
}

std::vector<RotaryAxis> axes(const json& doc, const char* key, bool on_head,
                             const std::string& src) {
  std::vector<RotaryAxis> out;
  if (!doc.contains(key)) return out;
  const json& list = doc[key];
  const std::string w = src + ": " + key;
  if (!list.is_array()) throw InvalidArgument(w + " must be an array of axes");
  if (list.size() > 2)
    throw InvalidArgument(w + " has " + std::to_string(list.size()) + " axes (at most 2 per side)");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& a = list[i];
    const std::string wi = w + "[" + std::to_string(i) + "]";
    if (!a.is_object()) throw InvalidArgument(wi + " must be an object");
    for (auto it = a.begin(); it != a.end(); ++it)
      if (it.key() != "name" && it.key() != "direction" && it.key() != "point" &&
          it.key() != "limits_deg")
        throw InvalidArgument(wi + "." + it.key() +
                              " is not a field of an axis (name, direction, point, limits_deg)");
    if (!a.contains("name") || !a["name"].is_string())
      throw InvalidArgument(wi + ".name is missing (the controller's letter of the axis)");
    const std::string name = a["name"].get<std::string>();
    if (name != "A" && name != "B" && name != "C")
      throw InvalidArgument(
          wi + ".name '" + name.substr(0, 16) +
          "' must be A, B or C (the rotary axis words of ISO 6983; a nutating axis "
          "keeps its controller letter and gets the U/V error names)");
    if (!a.contains("direction")) throw InvalidArgument(wi + ".direction is missing");
    const Eigen::Vector3d dir = vector3(a["direction"], wi + ".direction");
    const Eigen::Vector3d pt =
        a.contains("point") ? vector3(a["point"], wi + ".point") : Eigen::Vector3d::Zero();
    std::optional<std::array<double, 2>> lim;
    if (a.contains("limits_deg")) lim = pair(a["limits_deg"], wi + ".limits_deg");
    out.push_back(make_rotary_axis(name[0], dir, pt, on_head, lim, wi));
  }
  return out;
}

}  // namespace

MachineDescription parse_machine_description(const std::string& json_text,
                                             const std::string& source) {
  json doc;
  try {
    doc = parse_json(json_text, source);  // strict, bounded in depth and size (core/json_text.hpp)
  } catch (const ParseError& e) {         // syntax, depth, and numbers beyond double (1e999)
    throw InvalidArgument(e.what());
  }
  if (!doc.is_object()) throw InvalidArgument(source + ": a machine description is a JSON object");
  if (!doc.contains("format") || doc["format"] != "rotacal-machine/1")
    throw InvalidArgument(source + ": format must be \"rotacal-machine/1\"");
  static const std::set<std::string> known = {
      "format", "name", "table_axes", "head_axes", "pivot_length", "tool_length", "travel_mm"};
  for (auto it = doc.begin(); it != doc.end(); ++it)
    if (!known.count(it.key()))
      throw InvalidArgument(source + ": " + it.key() + " is not a field of rotacal-machine/1");
  MachineDescription d;
  d.name =
      doc.contains("name") && doc["name"].is_string() ? doc["name"].get<std::string>() : "custom";
  d.table_axes = axes(doc, "table_axes", false, source);
  d.head_axes = axes(doc, "head_axes", true, source);
  const std::size_t n = d.table_axes.size() + d.head_axes.size();
  if (n != 2)
    throw InvalidArgument(source + ": table_axes and head_axes hold " + std::to_string(n) +
                          " rotary axes; a 5-axis machine has 2");
  if (d.axis(0).name == d.axis(1).name)
    throw InvalidArgument(source + ": two axes are named '" + std::string(1, d.axis(0).name) +
                          "' (axis names must differ)");
  if (std::abs(std::abs(d.axis(0).direction.dot(d.axis(1).direction)) - 1.0) < 1e-9)
    throw InvalidArgument(source + ": the directions of " + std::string(1, d.axis(0).name) +
                          " and " + std::string(1, d.axis(1).name) +
                          " are parallel; they cannot orient a tool");
  for (const char* k : {"pivot_length", "tool_length"})
    if (doc.contains(k)) {
      const double v = finite_number(doc[k], source + ": " + k);
      if (v < 0 || v > 2000) throw InvalidArgument(source + ": " + k + " must lie in [0, 2000] mm");
      (std::string(k) == "pivot_length" ? d.pivot_length : d.tool_length) = v;
    }
  if (doc.contains("travel_mm")) {
    const json& t = doc["travel_mm"];
    if (!t.is_array() || t.size() != 3)
      throw InvalidArgument(source +
                            ": travel_mm must be [[xmin, xmax], [ymin, ymax], [zmin, zmax]]");
    Eigen::Matrix<double, 3, 2> m;
    for (int k = 0; k < 3; ++k) {
      const auto p =
          pair(t[static_cast<std::size_t>(k)], source + ": travel_mm[" + std::to_string(k) + "]");
      m(k, 0) = p[0];
      m(k, 1) = p[1];
    }
    d.travel_mm = m;
  }
  return d;
}

std::string machine_description_json(const MachineDescription& d) {
  auto vec = [](const Eigen::Vector3d& v) {  // + 0.0 turns -0 into 0 (a cleaner file, same value)
    return json::array({v[0] + 0.0, v[1] + 0.0, v[2] + 0.0});
  };
  auto axes_json = [&](const std::vector<RotaryAxis>& list) {
    json out = json::array();
    for (const RotaryAxis& a : list) {
      json j = {{"name", std::string(1, a.name)},
                {"direction", vec(a.direction)},
                {"point", vec(a.point)}};
      if (a.limits_deg) j["limits_deg"] = {(*a.limits_deg)[0], (*a.limits_deg)[1]};
      out.push_back(j);
    }
    return out;
  };
  json doc = {{"format", "rotacal-machine/1"},         {"name", d.name},
              {"table_axes", axes_json(d.table_axes)}, {"head_axes", axes_json(d.head_axes)},
              {"pivot_length", d.pivot_length},        {"tool_length", d.tool_length}};
  if (d.travel_mm) {
    const auto& t = *d.travel_mm;
    doc["travel_mm"] = {{t(0, 0), t(0, 1)}, {t(1, 0), t(1, 1)}, {t(2, 0), t(2, 1)}};
  }
  return doc.dump();  // one line; numbers in the shortest form that reads back exactly
}

namespace {

MachineDescription builtin(const std::string& name, std::vector<RotaryAxis> table,
                           std::vector<RotaryAxis> head, double pivot_length, double tool_length,
                           const Eigen::Matrix<double, 3, 2>& travel) {
  MachineDescription d;
  d.name = name;
  d.table_axes = std::move(table);
  d.head_axes = std::move(head);
  d.pivot_length = pivot_length;
  d.tool_length = tool_length;
  d.travel_mm = travel;
  return d;
}

const std::vector<MachineDescription>& builtins() {
  static const std::vector<MachineDescription> all = [] {
    const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                          Z = Eigen::Vector3d::UnitZ(), O = Eigen::Vector3d::Zero();
    using Lim = std::optional<std::array<double, 2>>;
    const Lim endless = std::nullopt;
    const Lim swivel = std::array<double, 2>{-110.0, 110.0};
    Eigen::Matrix<double, 3, 2> trt, head;
    trt << -400, 400, -300, 300, -300, 400;
    head << -600, 600, -400, 400, -200, 700;
    auto T = [](char n, const Eigen::Vector3d& d, const Eigen::Vector3d& p, Lim l) {
      return make_rotary_axis(n, d, p, false, l, std::string("built-in axis ") + n);
    };
    auto H = [](char n, const Eigen::Vector3d& d, const Eigen::Vector3d& p, Lim l) {
      return make_rotary_axis(n, d, p, true, l, std::string("built-in axis ") + n);
    };
    std::vector<MachineDescription> v;
    // The two table machines of formats.md; their rotary limits are left open, as they
    // were before descriptions existed (files and plans keep their meaning).
    v.push_back(builtin("AC-trt", {T('A', X, O, endless), T('C', Z, O, endless)}, {}, 0, 0, trt));
    v.push_back(builtin("BC-trt", {T('B', Y, O, endless), T('C', Z, O, endless)}, {}, 0, 0, trt));
    // B swivel head over a C rotary table; the B line passes through the controlled point.
    v.push_back(
        builtin("B-head-C-table", {T('C', Z, O, endless)}, {H('B', Y, O, swivel)}, 150, 100, head));
    // Fork heads: C carries the swivel (A or B); both lines through the controlled point.
    v.push_back(
        builtin("AC-head", {}, {H('C', Z, O, endless), H('A', X, O, swivel)}, 150, 100, head));
    v.push_back(
        builtin("BC-head", {}, {H('C', Z, O, endless), H('B', Y, O, swivel)}, 150, 100, head));
    // Nutating table: a B axis at 45 degrees in the YZ plane carrying a C table; turning B by
    // 180 degrees stands the C table vertical.
    v.push_back(builtin(
        "B45C-trt",
        {T('B', Eigen::Vector3d(0, -1, 1).normalized(), O, std::array<double, 2>{0.0, 180.0}),
         T('C', Z, O, endless)},
        {}, 0, 0, trt));
    return v;
  }();
  return all;
}

}  // namespace

const std::vector<std::string>& builtin_machine_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const MachineDescription& d : builtins()) n.push_back(d.name);
    return n;
  }();
  return names;
}

const MachineDescription* builtin_machine(const std::string& name) {
  for (const MachineDescription& d : builtins())
    if (d.name == name) return &d;
  return nullptr;
}

}  // namespace rotacal
