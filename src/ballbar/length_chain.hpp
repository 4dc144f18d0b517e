// SPDX-License-Identifier: BSD-3-Clause
// The ballbar reading's derivatives by the chain rule through the stages of effects.hpp, for a
// machine without head axes and one pivot: the fit's Jacobian with effects (length_model.hpp)
// and the diagnosis' candidate Jacobians (src/diagnose/ballbar_sensitivities.hpp).
//
// Why: Jets of every parameter through the whole model were the largest part of a diagnosis
// (the fits with effects took Jets of width 16 through both axis rotations for every row).
// An effect enters the reading only at a few places: an axis' angle, the pose of an axis'
// error motion E or coning K (a left rotation and a translation), the table's translation D,
// the tool-side ball and the reading itself. So
//   dL/dq = sum over places of (dL / d place: one backward pass per row, in doubles)
//         x (d place / dq: the effects' stages alone, by Jets).
// The location errors and the pivot take the backward pass' derivatives of the rotations
// (LineRotationDerivatives, as the analytic path). The same derivatives as the Jets up to
// rounding: tests/cpp/test_ballbar_identify.cpp and test_diagnose_ballbar.cpp compare them.
#pragma once

#include <ceres/jet.h>

#include <Eigen/Core>

#include "rotacal/kinematics/effects.hpp"

namespace rotacal::length_chain {

/// The places: the angle of chain axes 0 and 1; E's translation and left rotation (3 each) of
/// axes 0 and 1; K's left rotation of axes 0 and 1; the table translation D; the tool-side
/// ball; the reading.
enum Place {
  kAngle = 0,
  kEt = 2,
  kEw = 8,
  kKw = 14,
  kD = 20,
  kTool = 23,
  kReading = 26,
  kPlaces = 27
};
using Places = Eigen::Matrix<double, kPlaces, 1>;
using Jet4 = ceres::Jet<double, 4>;

/// Whether the chain rule handles machine m (its ball pivot goes through every rotary axis).
inline bool supports(MachineType m) { return !m.description().has_head(); }

/// One sample: commanded xyz (mm), angles (rad), time (s) and motion.
struct Sample {
  const Eigen::Vector3d& xyz;
  const RotaryAngles<double>& angles;
  double time;
  const RotaryMotion& motion;
};

/// dL / d(each place) of one sample on the machine with location errors e, pivot and effects
/// fx (parameters q); with `base`, also dL / d(the 8 location errors, the 3 pivot coordinates).
void sensitivities(MachineType m, const LocationErrors<double>& e, const Eigen::Vector3d& pivot,
                   const EffectModel& fx, const double* q, const Sample& s, Places& out,
                   Eigen::Matrix<double, 1, 11>* base);

/// d(each place) / d(the Jets' N seeds) of effects fx at parameters q (Jets) for one sample.
/// A rotation's place is its left derivative: dR = [dw]x R. N = 1 or 4 (length_chain.cpp):
/// a Jet's derivative parts are computed element by element, so both widths give the same bits.
template <int N>
void place_derivatives(MachineType m, const EffectModel& fx, const ceres::Jet<double, N>* q,
                       const Sample& s, Eigen::Matrix<double, kPlaces, N>& d);

}  // namespace rotacal::length_chain
