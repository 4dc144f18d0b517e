#pragma once
/// \file
/// Kinematics of a tilting-rotary table (AC-trt, BC-trt) with the eight ISO 230-7 location
/// errors, exactly as ../shared/spec/formats.md defines them. This is the one definition of
/// the table's rigid motion: simulator, toolpaths, fits and compensation all call it.
///
/// Frames: machine frame with origin at the nominal intersection of the rotary axes; table
/// frame fixed to the innermost (C) table, equal to the machine frame at all rotary axes 0.
/// Angles in rad, lengths in mm.

#include <array>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/rotation.hpp"

namespace rotacal {

/// Table kinematics. The tilt axis (A about X, or B about Y) carries the C table.
enum class MachineType { AC_trt, BC_trt };

/// "AC-trt" / "BC-trt".
std::string to_string(MachineType m);
/// Inverse of to_string; throws InvalidArgument naming the unknown text.
MachineType parse_machine_type(const std::string& s);
/// 'A' for AC-trt, 'B' for BC-trt.
char tilt_axis_letter(MachineType m);

/// The eight location errors of one machine, in a fixed order:
///   index 0, 1: position of the tilt-axis line; 2, 3: orientation of the tilt axis;
///   index 4, 5: position of the C-axis line;    6, 7: orientation of the C axis.
/// AC-trt: E_Y0A E_Z0A E_B0A E_C0A E_X0C E_Y0C E_A0C E_B0C (Flynn et al., Table 1 order)
/// BC-trt: E_X0B E_Z0B E_A0B E_C0B E_X0C E_Y0C E_A0C E_B0C
/// Positions in mm, orientations in rad.
template <typename Scalar>
struct LocationErrors {
  static constexpr int kSize = 8;
  Eigen::Matrix<Scalar, kSize, 1> v = Eigen::Matrix<Scalar, kSize, 1>::Zero();

  LocationErrors() = default;
  explicit LocationErrors(const Eigen::Matrix<Scalar, kSize, 1>& values) : v(values) {}
  /// View of a raw parameter block (e.g. a Ceres parameter pointer).
  static LocationErrors from_ptr(const Scalar* p) {
    return LocationErrors(Eigen::Map<const Eigen::Matrix<Scalar, kSize, 1>>(p));
  }
  template <typename Other>
  LocationErrors<Other> cast() const {
    return LocationErrors<Other>(v.template cast<Other>());
  }
};

/// ISO 230-7 names in LocationErrors order for the given machine.
const std::array<std::string, 8>& location_error_names(MachineType m);
/// Index of an ISO 230-7 name for the machine; throws InvalidArgument if it is not one of its 8.
int location_error_index(MachineType m, const std::string& name);
/// True for the four orientation errors (rad), false for the four positions (mm).
inline bool location_error_is_angle(int index) { return index == 2 || index == 3 || index >= 6; }

/// An axis line: a point it passes through and a (not necessarily unit) direction.
template <typename Scalar>
struct AxisLine {
  Vec3<Scalar> point;
  Vec3<Scalar> direction;
};

/// Actual tilt-axis line (A or B) in the machine frame at all rotary axes 0 (formats.md table).
template <typename Scalar>
AxisLine<Scalar> tilt_axis_line(MachineType m, const LocationErrors<Scalar>& e) {
  const Scalar zero(0), one(1);
  if (m == MachineType::AC_trt)  // through (0, E_Y0A, E_Z0A), along (1, E_C0A, -E_B0A)
    return {Vec3<Scalar>(zero, e.v[0], e.v[1]), Vec3<Scalar>(one, e.v[3], -e.v[2])};
  // BC-trt: through (E_X0B, 0, E_Z0B), along (-E_C0B, 1, E_A0B)
  return {Vec3<Scalar>(e.v[0], zero, e.v[1]), Vec3<Scalar>(-e.v[3], one, e.v[2])};
}

/// Actual C-axis line in the machine frame at all rotary axes 0:
/// through (E_X0C, E_Y0C, 0), along (E_B0C, -E_A0C, 1) for both machines.
template <typename Scalar>
AxisLine<Scalar> c_axis_line(MachineType /*m*/, const LocationErrors<Scalar>& e) {
  return {Vec3<Scalar>(e.v[4], e.v[5], Scalar(0)), Vec3<Scalar>(e.v[7], -e.v[6], Scalar(1))};
}

/// Rotary axis positions of a tilting-rotary table (rad). `tilt` is A or B, `rot` is C
/// (absolute: machine frame at tilt = 0).
template <typename Scalar>
struct RotaryAngles {
  Scalar tilt = Scalar(0);
  Scalar rot = Scalar(0);
};

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
/// Rot(tilt line, tilt) * Rot(C line, rot) * q_table, exact rotations about the actual lines.
/// (kinematics/effects.hpp inserts error motions between these two stages.)
template <typename Scalar>
Pose<Scalar> table_pose(MachineType m, const LocationErrors<Scalar>& e,
                        const RotaryAngles<Scalar>& angles) {
  return tilt_axis_motion(m, e, angles.tilt) * c_axis_motion(m, e, angles.rot);
}

/// Forward kinematics: machine-frame position of a point fixed on the table.
template <typename Scalar>
Vec3<Scalar> forward(MachineType m, const LocationErrors<Scalar>& e,
                     const RotaryAngles<Scalar>& angles, const Vec3<Scalar>& q_table) {
  return table_pose(m, e, angles) * q_table;
}

/// Machine axis command: linear axes X, Y, Z (mm) of the tool-side ball and rotary angles (rad).
struct MachineAxes {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  RotaryAngles<double> angles;
};

/// Inverse kinematics for a ball tool (orientation does not matter): the machine axes that put
/// the tool-side ball at `p_table` (table frame) with the table at `angles`, on a machine
/// with location errors `e`. With e = 0 this is the nominal TCPM transform; with identified
/// errors it is the compensated command.
MachineAxes inverse(MachineType m, const LocationErrors<double>& e,
                    const RotaryAngles<double>& angles, const Eigen::Vector3d& p_table);

/// Inverse kinematics with tool orientation: rotary angles that align the table-frame
/// direction `k_table` with the spindle (machine +Z) on the machine with errors `e`, and the
/// linear axes that put the tool-side ball at `p_table`. `positive_tilt` picks the branch
/// with tilt >= 0 (the other solution has the opposite tilt and C + pi). Throws
/// InvalidArgument if k_table is zero; near the singular pose (k along C) C is kept at
/// `rot_hint`. Solved in closed form for e = 0, refined by Gauss-Newton for e != 0.
MachineAxes inverse_with_tool_axis(MachineType m, const LocationErrors<double>& e,
                                   const Eigen::Vector3d& p_table, const Eigen::Vector3d& k_table,
                                   bool positive_tilt = true, double rot_hint = 0.0);

}  // namespace rotacal
