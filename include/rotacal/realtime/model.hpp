// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A fitted model as the controller's real-time path holds it: fixed size, no pointers, no
/// text, nothing to free. It is a chain and an effect list of kinematics/chain_stages.hpp, so
/// the real-time evaluation (realtime/evaluate.hpp) runs the same formulas as the fits.
/// Filled by realtime/blob.hpp's reader (a controller) or by the library's exporter.

#include <Eigen/Core>

#include "rotacal/kinematics/chain_stages.hpp"

namespace rotacal {
namespace realtime {

/// Capacity of a model: the catalogue of one machine up to harmonic 8 fits in it.
constexpr int kMaxEffects = 128;
constexpr int kMaxParams = 384;

/// One rotary axis: what RotaryAxis (kinematics/machine_description.hpp) holds that moves
/// anything, without the names and limits.
struct Axis {
  char name = 'C';  ///< A, B or C
  bool on_head = false;
  int principal = -1;  ///< 0..2 when along X, Y, Z; -1 for a nutating axis
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< nominal, unit
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       ///< nominal, mm
  Eigen::Matrix<double, 3, 2> position_basis = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix<double, 3, 2> direction_basis = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Vector3d radial1 = Eigen::Vector3d::UnitX(), radial2 = Eigen::Vector3d::UnitY();
};

/// One catalogue effect (the fields of Effect, effects.hpp, that the formulas read).
struct Term {
  EffectKind kind = EffectKind::rotary_zero_offset;
  char axis = 0;
  int harmonic = 0;
  char direction = 0;
};

/// The whole identified model of one machine.
struct Model {
  Axis axes[2];                   ///< chain order: table axes from the bed outwards, then head axes
  int table_axes = 2;             ///< 0, 1 or 2
  int rot = 1;                    ///< chain index of the rotary (C-like) axis
  double pivot_length = 0;        ///< mm, head machines: controlled point to spindle nose
  LocationErrors<double> errors;  ///< location_error_names order, mm / rad
  /// Thermal gains (effects.md thermal_location_R): error i is errors[i] + gain(i, 0) y1 +
  /// gain(i, 1) y2, y1 and y2 the lag states the controller integrates. Zero when the model has
  /// no thermal term.
  Eigen::Matrix<double, 8, 2> thermal_gain = Eigen::Matrix<double, 8, 2>::Zero();
  Term effects[kMaxEffects];
  int num_effects = 0;
  double params[kMaxParams] = {};
  int num_params = 0;
  Eigen::Vector3d linear_reference = Eigen::Vector3d::Zero();  ///< a_ref of effects.md, mm

  // The chain of chain_stages.hpp.
  const Axis& axis(int k) const { return axes[k]; }
  int rot_index() const { return rot; }
  int num_table_axes() const { return table_axes; }
  bool has_head() const { return table_axes < 2; }
};

/// Joint positions: linear axes X, Y, Z (mm; the controlled point) and the rotary axes (rad).
struct Joints {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  RotaryAngles<double> angles;
};

/// What the model depends on besides the joints.
struct State {
  double tool_length = 0;  ///< mm: spindle nose to tool tip (head machines), or the tip below
                           ///< the controlled point (table-table machines, 0: X, Y, Z is the tip)
  double y1 = 0, y2 = 0;   ///< thermal lag states (dimensionless)
  double t = 0;            ///< s, time of the thermal_drift / thermal_warmup terms
  RotaryMotion motion;     ///< the axes' motion (backlash, servo lag, reversal spikes)
};

/// The tool relative to the workpiece (the frame of the innermost table axis).
struct ToolPose {
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();         ///< mm
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit, spindle +Z
};

}  // namespace realtime
}  // namespace rotacal
