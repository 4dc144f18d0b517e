// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The ballbar problem: the one parameter layout and the one residual of every ballbar fit
/// (identification, Monte Carlo, design, diagnosis and its uncertainty budget).
///
/// Layout (core/parameter_layout.hpp), in vector order:
///   location_errors  8, location_error_names(machine) order (mm, rad)
///   pivot            3 per centre pivot (items of 3, table frame, mm)
///   effects          the effect model's parameters (kinematics/effects.hpp order)
/// Residual, per sample: r = L_model - L_measured (mm), L_model = predicted_length (model.hpp).

#include <string>
#include <vector>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/model.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"

namespace rotacal {

/// The blocks of a ballbar parameter vector.
struct BallbarLayout {
  ParameterLayout all;
  ParameterBlock errors;   ///< "location_errors"
  ParameterBlock pivots;   ///< "pivot": items of 3, one per centre pivot
  ParameterBlock effects;  ///< "effects"
};

/// [location errors, `pivots` centre pivots, fx's parameters]. One pivot is named pivot_x,
/// pivot_y, pivot_z; several pivot_x#1, ... (1-based, in pivot order).
BallbarLayout ballbar_layout(MachineType m, const EffectModel& fx, int pivots = 1);

/// r = L_model - L_measured (mm) of one sample whose ball pivot is item `pivot` of the pivot
/// block, parameters p in `L`'s order (doubles or Jets).
template <typename T>
T ballbar_residual(const BallbarLayout& L, MachineType m, const EffectModel& fx, const T* p,
                   Eigen::Index pivot, const Eigen::Vector3d& xyz,
                   const RotaryAngles<double>& angles, double t, const RotaryMotion& motion,
                   double measured) {
  const T* c = p + L.pivots.item_offset(pivot);
  return predicted_length<T>(m, LocationErrors<T>::from_ptr(L.errors.ptr(p)),
                             Vec3<T>(c[0], c[1], c[2]), fx, L.effects.ptr(p), xyz, angles, t,
                             motion) -
         T(measured);
}

/// The same for row i of `d` (its motion, when built with it).
template <typename T>
T ballbar_residual(const BallbarLayout& L, const BallbarArrays& d, const EffectModel& fx,
                   const T* p, Eigen::Index i, Eigen::Index pivot = 0) {
  const std::size_t k = static_cast<std::size_t>(i);
  return ballbar_residual<T>(L, d.machine, fx, p, pivot, d.xyz.col(i), d.angles[k], d.time[i],
                             d.motion.empty() ? RotaryMotion{} : d.motion[k], d.length[i]);
}

/// The unknowns (names, units, start values), effects and solver settings of a ballbar joint
/// fit of one set-up. Throws InvalidArgument for an effect that does not exist on the machine
/// or fewer samples than unknowns.
struct BallbarFitSetup {
  EffectModel effects;
  BallbarLayout layout;
  std::vector<FitParameter> parameters;
  JointFitSettings settings;
};

BallbarFitSetup ballbar_fit_setup(const BallbarArrays& data, const JointFitOptions& options);

/// The machine model at a solution `x` of a fit with `setup` (pivot: the first).
BallbarMachineModel ballbar_model_at(const BallbarFitSetup& setup, MachineType m,
                                     const Eigen::VectorXd& x);

}  // namespace rotacal
