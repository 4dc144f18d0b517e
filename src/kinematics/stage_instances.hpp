// SPDX-License-Identifier: BSD-3-Clause
// The effects' stages that the ballbar diagnosis' chain rule
// (src/diagnose/ballbar_sensitivities.cpp) calls directly, compiled once in effects_instances.cpp,
// where table_point and tool_position instantiate them anyway: declared extern there, the chain
// rule's file does not compile them again (a few CPU-s of build time).
#pragma once

#include "rotacal/kinematics/effects.hpp"

/// `EXTERN template` declarations (EXTERN = extern) or definitions (EXTERN empty) for scalar S.
#define ROTACAL_STAGE_INSTANCES(EXTERN, S)                                            \
  EXTERN template detail::AxisStages<S> detail::axis_stages<S>(                       \
      MachineType, const EffectModel&, const S*, const RotaryAngles<double>&, double, \
      const RotaryMotion&);                                                           \
  EXTERN template Vec3<S> linear_axes_position<S>(const EffectModel&, const S*,       \
                                                  const Eigen::Vector3d&, const S&);  \
  EXTERN template Vec3<S> tool_offset<S>(const EffectModel&, const S*);

/// The scalars: the fit's doubles and the Jets of widths 1 (one-seed candidates) and 4.
#define ROTACAL_STAGE_SCALARS(EXTERN)               \
  ROTACAL_STAGE_INSTANCES(EXTERN, double)           \
  ROTACAL_STAGE_INSTANCES(EXTERN, detail::JetOf<1>) \
  ROTACAL_STAGE_INSTANCES(EXTERN, detail::JetOf<4>)
