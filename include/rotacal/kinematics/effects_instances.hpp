// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The catalogue's table and tool motion (effects.hpp: table_pose, table_point, tool_position,
/// and through them axis_stages and the rotations) compiled once per scalar type the library
/// uses, in src/kinematics/effects_instances.cpp, instead of in every file that fits, simulates
/// or diagnoses. The scalars: double, the diagnosis' candidate Jets
/// (widths 1 to 4, candidate_jets.hpp) and evaluate_with_jets' passes (4, 8, 12, 16,
/// joint_fit.hpp). Another scalar still works: it is compiled where it is used.
/// Included at the end of effects.hpp; not meant to be included by name.

#include <ceres/jet.h>

#include "rotacal/kinematics/effects.hpp"

/// `EXTERN template` declarations (EXTERN = extern) or definitions (EXTERN empty) of the
/// effects' entry points for scalar S.
#define ROTACAL_EFFECTS_INSTANCES(EXTERN, S)                                                       \
  EXTERN template Pose<S> table_pose<S>(MachineType, const LocationErrors<S>&, const EffectModel&, \
                                        const S*, const RotaryAngles<double>&, double,             \
                                        const RotaryMotion&);                                      \
  EXTERN template Vec3<S> table_point<S>(                                                          \
      MachineType, const LocationErrors<S>&, const EffectModel&, const S*,                         \
      const RotaryAngles<double>&, double, const Vec3<S>&, const RotaryMotion&);                   \
  EXTERN template Vec3<S> tool_position<S>(                                                        \
      MachineType, const LocationErrors<S>&, const EffectModel&, const S*, const Eigen::Vector3d&, \
      const RotaryAngles<double>&, double, const S&, const RotaryMotion&);

/// Applies F(EXTERN, S) to each scalar of the list above (a Jet's comma would split the
/// macro argument, hence the alias).
#define ROTACAL_EFFECTS_SCALARS(F, EXTERN) \
  F(EXTERN, double)                        \
  F(EXTERN, detail::JetOf<1>)              \
  F(EXTERN, detail::JetOf<2>)              \
  F(EXTERN, detail::JetOf<3>)              \
  F(EXTERN, detail::JetOf<4>)              \
  F(EXTERN, detail::JetOf<8>)              \
  F(EXTERN, detail::JetOf<12>)             \
  F(EXTERN, detail::JetOf<16>)

namespace rotacal {
namespace detail {
template <int N>
using JetOf = ceres::Jet<double, N>;
}  // namespace detail
ROTACAL_EFFECTS_SCALARS(ROTACAL_EFFECTS_INSTANCES, extern)
}  // namespace rotacal
