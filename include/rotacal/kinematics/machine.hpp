// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Kinematics of any 5-axis machine with two rotary axes (table-table, head-table, head-head)
/// and the eight location errors of its two axes, exactly as ../shared/spec/formats.md ("Any
/// 5-axis machine") defines them. This is the one definition of the rigid motion: simulators,
/// toolpaths, fits, NC writers and compensation all call it. The machine itself is a
/// MachineDescription (machine_description.hpp); `MachineType` is a cheap handle to one.
///
/// Frames: machine frame (axes parallel to X, Y, Z; origin as formats.md fixes it); table
/// frame fixed to the innermost table, equal to the machine frame at all rotary axes 0.
/// Angles in rad, lengths in mm.

#include <array>
#include <limits>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/chain_stages.hpp"
#include "rotacal/kinematics/machine_description.hpp"
#include "rotacal/kinematics/rotation.hpp"

namespace rotacal {

/// Handle of a machine description, cheap to copy and compare (an index into a process-wide
/// table that never forgets). `MachineType::AC_trt` and `BC_trt` name the two table machines
/// of formats.md; `from_description` registers any other. Two handles are equal when their
/// descriptions have the same name and kinematics.
class MachineType {
 public:
  static const MachineType AC_trt;
  static const MachineType BC_trt;

  constexpr MachineType() = default;  ///< AC-trt
  /// The handle of a description (a built-in of the same name and kinematics keeps its own).
  /// Throws InvalidArgument when the process already holds 4096 different machines.
  static MachineType from_description(const MachineDescription& d);
  const MachineDescription& description() const;
  constexpr int id() const { return id_; }
  constexpr bool operator==(const MachineType& o) const { return id_ == o.id_; }
  constexpr bool operator!=(const MachineType& o) const { return id_ != o.id_; }

  /// Chain index (0, 1) of the tilt axis and of the rotary axis (MachineDescription::rot_index).
  int tilt_index() const;
  int rot_index() const;
  bool has_head() const { return description().has_head(); }
  /// True for a built-in with a fixed `# machine:` name (files need no description line).
  bool is_builtin() const;

 private:
  constexpr explicit MachineType(int id) : id_(id) {}
  int id_ = 0;
};
constexpr MachineType MachineType::AC_trt{0};
constexpr MachineType MachineType::BC_trt{1};

/// The machine's name ("AC-trt", "B-head-C-table", the name of a description).
std::string to_string(MachineType m);
/// A built-in machine by name; throws InvalidArgument naming the unknown text and the
/// built-in names.
MachineType parse_machine_type(const std::string& s);
/// Letter of the tilt axis ('A' on AC-trt, 'B' on BC-trt and on a B head) and of the rotary
/// axis ('C' on every built-in).
char tilt_axis_letter(MachineType m);
char rot_axis_letter(MachineType m);

/// Location error names in LocationErrors order for the given machine (formats.md).
const std::array<std::string, 8>& location_error_names(MachineType m);

/// Names of the two R-test error maps of a machine (rtest/identify_joint.hpp), {tilt axis' map,
/// rotary axis' map}: the axis letter and the letter of what carries it (Oyama's "BY": B on the Y
/// slide, "CB": C on B). The axis nearest the bed rides the Y slide ("Y"), the head axis nearest
/// the linear axes the Z slide
/// ("Z"), any other the axis before it on its side. BC-trt: {"BY", "CB"}; AC-trt: {"AY", "CA"};
/// B-head-C-table: {"BZ", "CY"}; AC-head: {"AC", "CZ"}.
std::array<std::string, 2> rtest_map_names(MachineType m);
/// Index of a location error name for the machine; throws InvalidArgument if it is not one of
/// its 8.
int location_error_index(MachineType m, const std::string& name);
/// True for the four orientation errors (rad), false for the four positions (mm).
inline bool location_error_is_angle(int index) { return index == 2 || index == 3 || index >= 6; }

/// A MachineType as a chain of chain_stages.hpp: the formulas there read its axes through it.
struct MachineChain {
  const MachineDescription& d;
  int rot;
  explicit MachineChain(MachineType m) : d(m.description()), rot(m.rot_index()) {}
  const RotaryAxis& axis(int k) const { return d.axis(k); }
  int rot_index() const { return rot; }
  int num_table_axes() const { return static_cast<int>(d.table_axes.size()); }
  bool has_head() const { return d.has_head(); }
};

/// Actual line of chain axis k (0, 1) at all rotary axes 0: through p0 + dp along n + dn
/// (formats.md). Table axes in the machine frame, head axes relative to the controlled point.
template <typename Scalar>
AxisLine<Scalar> axis_line(MachineType m, int k, const LocationErrors<Scalar>& e) {
  return chain::axis_line(MachineChain(m), k, e);
}

/// Actual line of the tilt axis (A or B on the table machines) and of the rotary axis (C).
template <typename Scalar>
AxisLine<Scalar> tilt_axis_line(MachineType m, const LocationErrors<Scalar>& e) {
  return axis_line(m, m.tilt_index(), e);
}
template <typename Scalar>
AxisLine<Scalar> c_axis_line(MachineType m, const LocationErrors<Scalar>& e) {
  return axis_line(m, m.rot_index(), e);
}

/// Angle of chain axis k.
template <typename Scalar>
const Scalar& chain_angle(MachineType m, const RotaryAngles<Scalar>& a, int k) {
  return k == m.rot_index() ? a.rot : a.tilt;
}

/// Rigid motion of the tilt axis alone: exact rotation about its actual line.
template <typename Scalar>
Pose<Scalar> tilt_axis_motion(MachineType m, const LocationErrors<Scalar>& e, const Scalar& tilt) {
  const AxisLine<Scalar> T = tilt_axis_line(m, e);
  return rotation_about_line(T.point, T.direction, tilt);
}

/// Rigid motion of the C axis alone: exact rotation about its actual line.
template <typename Scalar>
Pose<Scalar> c_axis_motion(MachineType m, const LocationErrors<Scalar>& e, const Scalar& rot) {
  const AxisLine<Scalar> C = c_axis_line(m, e);
  return rotation_about_line(C.point, C.direction, rot);
}

/// Pose of the table frame in the machine frame: q_table -> p_machine =
/// Rot(T1 line, t1) * Rot(T2 line, t2) * q_table, exact rotations about the actual lines of
/// the table axes (identity without table axes). kinematics/effects.hpp inserts error
/// motions between these stages.
template <typename Scalar>
Pose<Scalar> table_pose(MachineType m, const LocationErrors<Scalar>& e,
                        const RotaryAngles<Scalar>& angles) {
  Pose<Scalar> T;
  const int n = static_cast<int>(m.description().table_axes.size());
  for (int k = 0; k < n; ++k) {
    const AxisLine<Scalar> L = axis_line(m, k, e);
    T = T * rotation_about_line(L.point, L.direction, chain_angle(m, angles, k));
  }
  return T;
}

/// Pose of the spindle relative to the controlled point X, Y, Z: Rot(H1 line, h1) *
/// Rot(H2 line, h2), exact rotations about the actual lines of the head axes (identity
/// without head axes).
template <typename Scalar>
Pose<Scalar> head_pose(MachineType m, const LocationErrors<Scalar>& e,
                       const RotaryAngles<Scalar>& angles) {
  Pose<Scalar> H;
  const MachineDescription& d = m.description();
  const int nt = static_cast<int>(d.table_axes.size()),
            n = nt + static_cast<int>(d.head_axes.size());
  for (int k = nt; k < n; ++k) {
    const AxisLine<Scalar> L = axis_line(m, k, e);
    H = H * rotation_about_line(L.point, L.direction, chain_angle(m, angles, k));
  }
  return H;
}

/// Ball centre relative to the spindle at all head axes 0: (0, 0, -(pivot_length +
/// tool_length + tool_length_error)); zero on a machine without head axes, where X, Y, Z is
/// the ball itself.
template <typename Scalar>
Vec3<Scalar> tool_vector(MachineType m, const Scalar& tool_length_error) {
  const MachineDescription& d = m.description();
  if (!d.has_head()) return Vec3<Scalar>::Zero();
  return Vec3<Scalar>(Scalar(0), Scalar(0),
                      -(Scalar(d.pivot_length + d.tool_length) + tool_length_error));
}

/// Forward kinematics: machine-frame position of a point fixed on the table.
template <typename Scalar>
Vec3<Scalar> forward(MachineType m, const LocationErrors<Scalar>& e,
                     const RotaryAngles<Scalar>& angles, const Vec3<Scalar>& q_table) {
  return table_pose(m, e, angles) * q_table;
}

/// Forward kinematics of the tool: machine-frame position of the ball for commanded linear
/// axes xyz (the controlled point) = xyz + head_pose * tool_vector (formats.md).
template <typename Scalar>
Vec3<Scalar> tool_ball(MachineType m, const LocationErrors<Scalar>& e,
                       const RotaryAngles<Scalar>& angles, const Vec3<Scalar>& xyz,
                       const Scalar& tool_length_error = Scalar(0)) {
  if (!m.has_head()) return xyz;
  return xyz + head_pose(m, e, angles) * tool_vector(m, tool_length_error);
}

/// Spindle direction (the tool's +Z) in the machine frame.
template <typename Scalar>
Vec3<Scalar> tool_direction(MachineType m, const LocationErrors<Scalar>& e,
                            const RotaryAngles<Scalar>& angles) {
  return head_pose(m, e, angles).R.col(2);
}

/// Machine axis command: linear axes X, Y, Z (mm; the ball on a table-table machine, the
/// controlled point on a machine with head axes) and rotary angles (rad).
struct MachineAxes {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  RotaryAngles<double> angles;
};

/// Inverse kinematics for a ball tool (orientation does not matter): the linear axes that
/// put the ball at `p_table` (table frame) with the rotary axes at `angles`, on a machine
/// with location errors `e`: xyz = table_pose * p_table - head_pose * tool_vector. With e = 0
/// this is the nominal TCPM transform; with identified errors it is the compensated command.
MachineAxes inverse(MachineType m, const LocationErrors<double>& e,
                    const RotaryAngles<double>& angles, const Eigen::Vector3d& p_table,
                    double tool_length_error = 0.0);

/// Where the ball of the command (xyz, angles) is, in the table frame:
/// table_pose^-1 * tool_ball (the inverse of `inverse`).
Eigen::Vector3d ball_in_table(MachineType m, const LocationErrors<double>& e,
                              const RotaryAngles<double>& angles, const Eigen::Vector3d& xyz,
                              double tool_length_error = 0.0);

/// Inverse kinematics with tool orientation: rotary angles that align the table-frame
/// direction `k_table` with the spindle on the machine with errors `e`, and the linear axes
/// that put the ball at `p_table`. `positive_tilt` picks the branch with tilt >= 0 (the other
/// branch has the opposite tilt). Throws InvalidArgument if k_table is zero or no pose of
/// the machine reaches it; at the singular pose (k along the rotary axis) the rotary angle
/// is kept at `rot_hint`. Solved in closed form for e = 0 (Paden-Kahan subproblem 2), refined
/// by Gauss-Newton for e != 0.
MachineAxes inverse_with_tool_axis(MachineType m, const LocationErrors<double>& e,
                                   const Eigen::Vector3d& p_table, const Eigen::Vector3d& k_table,
                                   bool positive_tilt = true, double rot_hint = 0.0);

}  // namespace rotacal
