// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Prediction with a fitted R-test joint model (identify_joint.hpp), e.g. one read back from a
/// model file: rebuilding the model from its parts with checks, and a whole session predicted.

#include <map>
#include <string>
#include <vector>

#include "rotacal/rtest/identify_joint.hpp"

namespace rotacal {

/// A joint model from its parts (as a model file stores them), on any machine. Throws
/// InvalidArgument naming the part when a basis degree is negative, the sizes disagree with
/// the basis (params: rtest_num_location_parameters(machine) + num_b_coefficients +
/// num_c_coefficients, i.e. 8 location errors, tool_offset_Z on a machine with head axes, then
/// the map coefficients; covariance square of that size; one observable flag per parameter), or
/// a value is not finite.
RtestJointModel make_rtest_joint_model(MachineType machine, const RtestBasis& basis,
                                       const Eigen::VectorXd& params,
                                       const Eigen::MatrixXd& covariance,
                                       const std::vector<bool>& observable);

/// Names of the prediction's 1-sigma columns (mm), appended to the session's extra columns.
inline const std::vector<std::string>& rtest_prediction_std_columns() {
  static const std::vector<std::string> names = {"dx_std", "dy_std", "dz_std"};
  return names;
}

/// The session with every dx,dy,dz replaced by the model's reading of its nest at its angles
/// (tilt B, rotary C; RtestJointModel::reading):
///   d = T(B, C)^-1 (xyz_nominal + H t) - q_nest + zero_setup
/// where zero_setup is probe_zeros[setup] if `probe_zeros` is not empty (every set-up must then
/// have one) and 0 otherwise (a new set-up's probe zero is unknown). Raw d1,d2,d3 are dropped
/// (they were measured, not predicted). The 1-sigma of each predicted component (parameter
/// covariance of the model, probe zero uncertainty not included) goes into extra columns
/// dx_std, dy_std, dz_std (replaced if present; empty where an unobservable parameter enters),
/// and a `prediction` metadata line says what was done. Throws InvalidArgument if the machines
/// differ, a set-up has no nest, or a probe zero is missing.
RtestSession predict_session(const RtestJointModel& model, const RtestSession& session,
                             const std::map<std::string, Eigen::Vector3d>& probe_zeros = {});

}  // namespace rotacal
