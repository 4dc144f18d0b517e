// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What a 5-axis machine is, as ../shared/spec/formats.md ("Any 5-axis machine") describes
/// it: a chain workpiece -> table rotary axes -> bed -> X, Y, Z -> head rotary axes -> tool,
/// with two rotary axes in all. Each axis has a controller letter, a nominal unit direction
/// and point, optional limits, and four location errors whose names and directions follow
/// the spec (ISO 230-7 names for an A, B or C axis along its principal direction; E_U0R,
/// E_V0R, E_DU0R, E_DV0R for any other axis). A `rotacal-machine/1` JSON file holds one.
///
/// Nothing here moves anything: kinematics/machine.hpp turns a description and the
/// location errors into the table pose and the tool position.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace rotacal {

/// One rotary axis of the chain.
struct RotaryAxis {
  char name = 'C';                                       ///< controller letter: A, B or C
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< nominal, unit
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       ///< nominal point on the line, mm
  std::optional<std::array<double, 2>> limits_deg;       ///< rotary limits, none: endless
  bool on_head = false;                                  ///< head side of the chain

  /// Location errors of the axis: the actual line passes through point + P * (e0, e1) along
  /// direction + N * (e2, e3) (formats.md). Columns of P and N are unit vectors.
  Eigen::Matrix<double, 3, 2> position_basis = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix<double, 3, 2> direction_basis = Eigen::Matrix<double, 3, 2>::Zero();
  std::array<std::string, 4> error_names;  ///< e0..e3 names
  /// Index 0..2 of X, Y, Z when the axis is the letter's principal axis (A along X, B along
  /// Y, C along Z, either sign); -1 for a nutating axis or a letter that does not match.
  int principal = -1;
  /// The frame of the axis' error motions (effects.md): radial directions d1, d2 and the
  /// axis n. For a principal axis d1, d2 are the cyclic pair (C: X, Y; A: Y, Z; B: Z, X);
  /// otherwise the spec's u, v.
  Eigen::Vector3d radial1 = Eigen::Vector3d::UnitX(), radial2 = Eigen::Vector3d::UnitY();
};

/// A rotary axis with its error basis and names worked out from letter and direction
/// (formats.md). Throws InvalidArgument naming `where` for a zero or non-finite direction.
RotaryAxis make_rotary_axis(char name, const Eigen::Vector3d& direction,
                            const Eigen::Vector3d& point, bool on_head,
                            std::optional<std::array<double, 2>> limits_deg,
                            const std::string& where);

/// The table-table / head-table / head-head chain with two rotary axes.
struct MachineDescription {
  std::string name;
  std::vector<RotaryAxis> table_axes;  ///< from the bed outwards (T1 carries T2)
  std::vector<RotaryAxis> head_axes;   ///< from the linear axes outwards (H1 carries H2)
  double pivot_length = 0.0;           ///< mm, head machines: controlled point to spindle nose
  double tool_length = 0.0;            ///< mm, spindle nose to the ball centre
  /// Travel of X, Y, Z (min, max per row), mm; none: not given.
  std::optional<Eigen::Matrix<double, 3, 2>> travel_mm;

  /// Axis k of the chain order: table axes, then head axes (the session's rotary columns).
  const RotaryAxis& axis(int k) const;
  bool has_head() const { return !head_axes.empty(); }
  bool has_table() const { return !table_axes.empty(); }
  /// "table-table", "head-table" or "head-head".
  std::string configuration() const;
  /// Chain index of the axis that is parallel to Z at all rotary axes 0 (the "rotary" axis
  /// whose angle does not change the tool's inclination, C on every built-in); when none or
  /// both are, the axis nearest the tool-workpiece interface. The other is the "tilt" axis.
  int rot_index() const;
  int tilt_index() const { return 1 - rot_index(); }
  /// The 8 location error names in LocationErrors order (chain order, 4 per axis).
  std::array<std::string, 8> location_error_names() const;
  /// Nominal ball centre relative to the controlled point, (0, 0, -(pivot + tool length)).
  Eigen::Vector3d tool_vector() const {
    return Eigen::Vector3d(0.0, 0.0, -(pivot_length + tool_length));
  }

  /// Everything that defines the kinematics (names of built-ins aside) is equal.
  bool same_kinematics(const MachineDescription& o) const;
};

/// Parse a `rotacal-machine/1` document. `source` names the file (or "# machine_description:
/// of FILE:LINE") in every message; the message names the field that is wrong (zero
/// direction, duplicate names, more than two axes, a letter outside A/B/C for a principal
/// direction, NaN, limits the wrong way round...).
MachineDescription parse_machine_description(const std::string& json_text,
                                             const std::string& source);
/// The description as `rotacal-machine/1` JSON on one line (for `# machine_description:`).
std::string machine_description_json(const MachineDescription& d);

/// Names of the built-in machines, in the order the docs draw them.
const std::vector<std::string>& builtin_machine_names();
/// A built-in machine by name; nullptr when there is none of that name.
const MachineDescription* builtin_machine(const std::string& name);

}  // namespace rotacal
