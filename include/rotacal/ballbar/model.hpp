// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The exact ballbar reading: the distance between the tool-side ball and the centre-pivot
/// ball, which sits at a fixed (unknown) point of the table. One definition, used by the
/// simulator, the joint fit, prediction and the diagnosis.

#include <vector>

#include "rotacal/ballbar/motion.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/kinematics/machine_model.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// Everything that determines a ballbar reading: the machine (kinematics/machine_model.hpp) and
/// the actual position of the centre-pivot ball on its table (table frame, mm), the one
/// quantity the ballbar set-up adds.
struct BallbarMachineModel : MachineModel {
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
};

/// Predicted centre-to-centre length (mm) for commanded linear axes xyz (mm) at rotary angles
/// `angles` (rad), time t (s) and motion of the rotary axes:
///   L = | p_tool(xyz, angles, t) - T(angles, t) * pivot | + reading error(t)
/// `tool_length_error` (mm) lengthens the tool of a machine with head axes (ignored otherwise).
template <typename Scalar>
Scalar predicted_length(MachineType m, const LocationErrors<Scalar>& e, const Vec3<Scalar>& pivot,
                        const EffectModel& fx, const Scalar* fx_params, const Eigen::Vector3d& xyz,
                        const RotaryAngles<double>& angles, double t, const RotaryMotion& motion,
                        const Scalar& tool_length_error = Scalar(0)) {
  const Vec3<Scalar> tool =
      tool_position(m, e, fx, fx_params, xyz, angles, t, tool_length_error, motion);
  const Vec3<Scalar> ball = table_point(m, e, fx, fx_params, angles, t, pivot, motion);
  return (tool - ball).norm() + ballbar_reading_error(fx, fx_params, t);
}

/// The same for one sample of a session, moving as `motion` says (rotary_motion of the
/// session, ballbar/motion.hpp).
template <typename Scalar>
Scalar predicted_length(MachineType m, const LocationErrors<Scalar>& e, const Vec3<Scalar>& pivot,
                        const EffectModel& fx, const Scalar* fx_params, const BallbarSample& s,
                        const RotaryMotion& motion, const Scalar& tool_length_error = Scalar(0)) {
  return predicted_length<Scalar>(m, e, pivot, fx, fx_params, s.xyz, s.angles_rad(), s.time, motion,
                                  tool_length_error);
}

/// Predicted lengths of every sample of a session on a machine model, the axes moving as the
/// samples' time and angle columns say (rotary_motion); the linear-axis polynomials about the
/// model's a_ref, unset: the mean commanded xyz of these samples (effects.md).
std::vector<double> predict_lengths(const BallbarMachineModel& model,
                                    const std::vector<BallbarSample>& samples);

}  // namespace rotacal
