// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/kinematics/machine.hpp"

#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace rotacal {

namespace {

// The process-wide table behind MachineType: built-ins first (AC-trt = 0, BC-trt = 1, in
// builtin_machine_names() order), then every other description met, never removed, so a
// handle stays valid for the life of the process and reading needs no lock.
struct Entry {
  MachineDescription d;
  std::array<std::string, 8> names;
  int tilt = 0, rot = 1;
  bool builtin = false;
};

constexpr int kMaxMachines = 4096;

struct Registry {
  std::array<std::atomic<const Entry*>, kMaxMachines> slots{};
  std::atomic<int> size{0};
  std::mutex write;
  std::vector<std::unique_ptr<Entry>> owned;

  Registry() {
    for (const std::string& n : builtin_machine_names()) add(*builtin_machine(n), true);
  }
  int add(const MachineDescription& d, bool builtin) {
    auto e = std::make_unique<Entry>();
    e->d = d;
    e->names = d.location_error_names();
    e->rot = d.rot_index();
    e->tilt = 1 - e->rot;
    e->builtin = builtin;
    const int id = size.load();
    if (id >= kMaxMachines)
      throw InvalidArgument("this process already holds " + std::to_string(kMaxMachines) +
                            " different machine descriptions");
    slots[static_cast<std::size_t>(id)].store(e.get());
    owned.push_back(std::move(e));
    size.store(id + 1);
    return id;
  }
};

Registry& registry() {
  static Registry r;
  return r;
}

const Entry& entry(MachineType m) {
  return *registry().slots[static_cast<std::size_t>(m.id())].load();
}

}  // namespace

MachineType MachineType::from_description(const MachineDescription& d) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.write);
  const int n = r.size.load();
  for (int i = 0; i < n; ++i) {
    const Entry& e = *r.slots[static_cast<std::size_t>(i)].load();
    if (e.d.name == d.name && e.d.same_kinematics(d)) return MachineType(i);
  }
  return MachineType(r.add(d, false));
}

const MachineDescription& MachineType::description() const { return entry(*this).d; }
int MachineType::tilt_index() const { return entry(*this).tilt; }
int MachineType::rot_index() const { return entry(*this).rot; }
bool MachineType::is_builtin() const { return entry(*this).builtin; }

std::string to_string(MachineType m) { return m.description().name; }

MachineType parse_machine_type(const std::string& s) {
  if (builtin_machine(s)) {
    const auto& names = builtin_machine_names();
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == s) return MachineType::from_description(*builtin_machine(s));
  }
  std::string known;
  for (const std::string& n : builtin_machine_names()) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument("unknown machine '" + s + "' (built-in: " + known +
                        "; any other needs a rotacal-machine/1 description)");
}

char tilt_axis_letter(MachineType m) { return m.description().axis(m.tilt_index()).name; }
char rot_axis_letter(MachineType m) { return m.description().axis(m.rot_index()).name; }

const std::array<std::string, 8>& location_error_names(MachineType m) { return entry(m).names; }

int location_error_index(MachineType m, const std::string& name) {
  const auto& names = location_error_names(m);
  for (int i = 0; i < 8; ++i)
    if (names[static_cast<std::size_t>(i)] == name) return i;
  throw InvalidArgument("'" + name + "' is not a location error of a " + to_string(m) + " machine");
}

MachineAxes inverse(MachineType m, const LocationErrors<double>& e,
                    const RotaryAngles<double>& angles, const Eigen::Vector3d& p_table,
                    double tool_length_error) {
  Eigen::Vector3d xyz = forward(m, e, angles, p_table);
  if (m.has_head()) xyz -= head_pose(m, e, angles) * tool_vector(m, tool_length_error);
  return {xyz, angles};
}

Eigen::Vector3d ball_in_table(MachineType m, const LocationErrors<double>& e,
                              const RotaryAngles<double>& angles, const Eigen::Vector3d& xyz,
                              double tool_length_error) {
  return table_pose(m, e, angles).inverse() * tool_ball(m, e, angles, xyz, tool_length_error);
}

namespace {

// Spindle direction seen in the table frame: table_pose^T * head_pose * e_z.
Eigen::Vector3d tool_axis_in_table(MachineType m, const LocationErrors<double>& e,
                                   const RotaryAngles<double>& a) {
  return table_pose(m, e, a).R.transpose() * tool_direction(m, e, a);
}

// Angle about unit axis w that turns x onto y (both projected on the plane normal to w);
// nullopt when either projection vanishes (the angle is free).
std::optional<double> turn_angle(const Eigen::Vector3d& w, const Eigen::Vector3d& x,
                                 const Eigen::Vector3d& y) {
  const Eigen::Vector3d xp = x - w * w.dot(x), yp = y - w * w.dot(y);
  if (xp.norm() < 1e-12 || yp.norm() < 1e-12) return std::nullopt;
  return std::atan2(w.dot(xp.cross(yp)), xp.dot(yp));
}

// Nominal rotary angles that bring the tool direction to k (table frame). Every
// configuration is one Paden-Kahan subproblem 2, Rot(a, alpha) Rot(b, beta) p = q:
//   table-table  Rot(T1, t1) Rot(T2, t2) k = e_z
//   head-table   Rot(H1, -h1) Rot(T1, t1) k = e_z
//   head-head    Rot(H1, h1) Rot(H2, h2) e_z = k
// z = Rot(b, beta) p = Rot(a, -alpha) q lies on both cones; its two solutions are the two
// branches.
RotaryAngles<double> nominal_angles(MachineType m, const Eigen::Vector3d& k, bool positive_tilt,
                                    double rot_hint) {
  const MachineDescription& d = m.description();
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d a, b, p, q;
  double alpha_sign = 1.0;  // alpha = alpha_sign * angle of the axis along a
  int ia = 0, ib = 1;       // chain indices of the axes along a and b
  if (d.table_axes.size() == 2) {
    a = d.axis(0).direction, b = d.axis(1).direction, p = k, q = ez;
  } else if (d.head_axes.size() == 2) {
    a = d.axis(0).direction, b = d.axis(1).direction, p = ez, q = k;
  } else {  // chain 0 is the table axis, chain 1 the head axis
    a = d.axis(1).direction, b = d.axis(0).direction, p = k, q = ez, alpha_sign = -1.0, ia = 1,
    ib = 0;
  }
  const double c = a.dot(b), s2 = 1.0 - c * c;
  const double x = (q.dot(a) - c * p.dot(b)) / s2, y = (p.dot(b) - c * q.dot(a)) / s2;
  const double g2 = (1.0 - x * x - y * y - 2.0 * x * y * c) / a.cross(b).squaredNorm();
  if (g2 < -1e-12)
    throw InvalidArgument("inverse_with_tool_axis: no pose of " + to_string(m) +
                          " turns the spindle to this tool direction");
  const double g = std::sqrt(std::max(0.0, g2));
  std::vector<RotaryAngles<double>> branches;
  for (double sg : {1.0, -1.0}) {
    const Eigen::Vector3d z = x * a + y * b + sg * g * a.cross(b);
    const auto beta = turn_angle(b, p, z), alpha = turn_angle(a, z, q);
    double ang[2];
    ang[ib] = beta.value_or(0.0);
    ang[ia] = alpha_sign * alpha.value_or(0.0);
    RotaryAngles<double> r{ang[m.tilt_index()], ang[m.rot_index()]};
    if (!beta || !alpha) r.rot = rot_hint;  // singular pose: the rotary axis is free
    branches.push_back(r);
  }
  for (const RotaryAngles<double>& r : branches)
    if (positive_tilt ? r.tilt >= -1e-15 : r.tilt <= 1e-15) return r;
  return branches.front();
}

}  // namespace

MachineAxes inverse_with_tool_axis(MachineType m, const LocationErrors<double>& e,
                                   const Eigen::Vector3d& p_table, const Eigen::Vector3d& k_table,
                                   bool positive_tilt, double rot_hint) {
  const double n = k_table.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    throw InvalidArgument("inverse_with_tool_axis: k_table must be a finite non-zero vector");
  const Eigen::Vector3d k = k_table / n;
  RotaryAngles<double> a = nominal_angles(m, k, positive_tilt, rot_hint);
  // Location errors are small (um, urad): a few Gauss-Newton steps on the tool direction converge.
  for (int it = 0; it < 10 && !e.v.isZero(0.0); ++it) {
    const Eigen::Vector3d r = tool_axis_in_table(m, e, a) - k;
    if (r.norm() < 1e-15) break;
    Eigen::Matrix<double, 3, 2> J;
    const double h = 1e-7;
    J.col(0) = (tool_axis_in_table(m, e, {a.tilt + h, a.rot}) - tool_axis_in_table(m, e, a)) / h;
    J.col(1) = (tool_axis_in_table(m, e, {a.tilt, a.rot + h}) - tool_axis_in_table(m, e, a)) / h;
    const Eigen::Vector2d step = J.colPivHouseholderQr().solve(-r);
    a.tilt += step[0];
    a.rot += step[1];
  }
  return inverse(m, e, a, p_table);
}

std::array<std::string, 2> rtest_map_names(MachineType m) {
  const MachineDescription& d = m.description();
  const int nt = static_cast<int>(d.table_axes.size());
  auto name = [&](int k) {
    const RotaryAxis& a = d.axis(k);
    char carrier = a.on_head ? 'Z' : 'Y';
    if (k != 0 && k != nt) carrier = d.axis(k - 1).name;  // the axis before it on its side
    return std::string(1, a.name) + carrier;
  };
  return {name(m.tilt_index()), name(m.rot_index())};
}

}  // namespace rotacal
