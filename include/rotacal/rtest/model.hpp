// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The R-test reading, one definition (Oyama & Ibaraki, Eq. 4, in the table frame), used by
/// the simulator, the joint fit, the paper-method checks and the diagnosis; the R-test
/// counterpart of ballbar/model.hpp:
///   d = T_machine_table^-1 * p_tool - q_nest          (+ the set-up's probe zero)
/// with T the actual table pose at the commanded angles, p_tool the actual sphere centre
/// (machine frame) and q_nest the nest's nominal sphere centre (table frame). Which table pose
/// depends on the model: the machine model of kinematics/effects.hpp (simulator, diagnosis),
/// location errors + Oyama's smooth error maps (joint fit, identify_joint.hpp), or Oyama's
/// Eqs. 5-7 alone (error_model.hpp).

#include <algorithm>
#include <vector>

#include "rotacal/kinematics/machine_model.hpp"

namespace rotacal {

/// Eq. 4: displacement of the sphere from the nest, table frame (mm).
template <typename Scalar>
Vec3<Scalar> rtest_displacement(const Pose<Scalar>& T_machine_table, const Vec3<Scalar>& p_tool,
                                const Eigen::Vector3d& q_nest) {
  return T_machine_table.R.transpose() * (p_tool - T_machine_table.t) - q_nest.cast<Scalar>();
}

/// The commanded linear axes for the nest at q_nest: the nominal machine puts the sphere there.
inline Eigen::Vector3d rtest_commanded_xyz(MachineType m, const Eigen::Vector3d& q_nest,
                                           const RotaryAngles<double>& angles) {
  return inverse(m, LocationErrors<double>(), angles, q_nest).xyz;
}

/// Reading on a machine with location errors e and effects fx (parameters fxp): the table
/// pose of kinematics/effects.hpp at the commanded angles (rad) and time t (s), and the tool
/// position for the commanded xyz (mm); `tool_length_error` (mm) on a machine with head axes.
template <typename Scalar>
Vec3<Scalar> rtest_reading(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                           const Scalar* fxp, const Eigen::Vector3d& xyz,
                           const RotaryAngles<double>& angles, double t,
                           const Eigen::Vector3d& q_nest,
                           const Scalar& tool_length_error = Scalar(0)) {
  return rtest_displacement<Scalar>(
      table_pose<Scalar>(m, e, fx, fxp, angles, t),
      tool_position<Scalar>(m, e, fx, fxp, xyz, angles, t, tool_length_error), q_nest);
}

/// Noise-free reading d (table frame, mm, no probe zero) of the nest at q_nest (table frame)
/// on `model` at commanded angles (rad) and time t (s), commanded as the nominal machine would.
inline Eigen::Vector3d rtest_reading(const MachineModel& model, const Eigen::Vector3d& q_nest,
                                     const RotaryAngles<double>& angles, double t) {
  return rtest_reading<double>(model.machine, model.errors, model.effects, model.effect_data(),
                               rtest_commanded_xyz(model.machine, q_nest, angles), angles, t,
                               q_nest);
}

/// Noise-free readings of the nest at q_nest at each pose (rad) and time (s). The linear-axis
/// polynomials are about the model's a_ref, unset: the mean commanded xyz of these poses.
inline std::vector<Eigen::Vector3d> rtest_readings(const MachineModel& model,
                                                   const Eigen::Vector3d& q_nest,
                                                   const std::vector<RotaryAngles<double>>& angles,
                                                   const std::vector<double>& times) {
  MachineModel m = model;
  if (!m.effects.linear_reference) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const RotaryAngles<double>& a : angles) sum += rtest_commanded_xyz(m.machine, q_nest, a);
    m.effects.linear_reference = sum / static_cast<double>(std::max<std::size_t>(angles.size(), 1));
  }
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < angles.size(); ++i)
    out.push_back(rtest_reading(m, q_nest, angles[i], times[i]));
  return out;
}

}  // namespace rotacal
