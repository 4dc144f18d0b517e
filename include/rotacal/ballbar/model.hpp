#pragma once
/// \file
/// The exact ballbar reading: the distance between the tool-side ball and the centre-pivot
/// ball, which sits at a fixed (unknown) point of the table. One definition, used by the
/// simulator, the joint fit, prediction and the diagnosis.

#include <vector>

#include "rotacal/io/session.hpp"
#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

/// Everything that determines a ballbar reading on a machine: location errors, the actual
/// pivot position (table frame, mm) and optional effects with their parameters.
struct BallbarMachineModel {
  MachineType machine = MachineType::AC_trt;
  LocationErrors<double> errors;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  EffectModel effects;
  std::vector<double> effect_params;  ///< effects.num_params() values
};

/// Predicted centre-to-centre length (mm) of one sample:
///   L = | p_tool(xyz, t) - T(angles, t) * pivot | + reading error(t)
template <typename Scalar>
Scalar predicted_length(MachineType m, const LocationErrors<Scalar>& e, const Vec3<Scalar>& pivot,
                        const EffectModel& fx, const Scalar* fx_params, const BallbarSample& s) {
  const Vec3<Scalar> tool = tool_position(fx, fx_params, s.xyz, s.time);
  const Vec3<Scalar> ball = table_point(m, e, fx, fx_params, s.angles_rad(), s.time, pivot);
  return (tool - ball).norm() + ballbar_reading_error(fx, fx_params, s.time);
}

/// Predicted lengths of every sample of a session on a machine model.
std::vector<double> predict_lengths(const BallbarMachineModel& model,
                                    const std::vector<BallbarSample>& samples);

}  // namespace rotacal
