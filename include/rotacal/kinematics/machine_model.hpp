// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A machine as every instrument sees it: its kinematics, its location errors, and the
/// catalogue effects (kinematics/effects.hpp) with their parameters. The ballbar and the
/// R-test simulate, fit and predict on this one struct.
///
/// Shaped for the general chain of ../shared/spec/formats.md ("Any 5-axis machine"): the
/// kinematics is named by `machine` and the location errors are one flat vector in the
/// order of `location_error_names(machine)`. A general chain will replace the enum with a
/// chain description whose axes carry their own named errors, keeping the flat
/// names/values/effects layout that the fits, model files and reports use.

#include <string>
#include <vector>

#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

struct MachineModel {
  MachineType machine = MachineType::AC_trt;
  LocationErrors<double> errors;  ///< mm / rad, location_error_names(machine) order
  /// On a machine with head axes, tool_offset_Z among the effects is minus the error of
  /// pivot_length + tool_length (only their sum is visible to a ball-ended instrument).
  EffectModel effects;
  std::vector<double> effect_params;  ///< effects.num_params() values, EffectModel layout

  /// A machine of this kinematics without location errors or effects.
  static MachineModel nominal(MachineType m) {
    MachineModel model;
    model.machine = m;
    return model;
  }

  /// Pointer to the effect parameters (nullptr when there are none), for the templated model.
  const double* effect_data() const {
    return effect_params.empty() ? nullptr : effect_params.data();
  }
  /// ISO 230-7 names of the location errors, then "id.name" of every effect parameter.
  std::vector<std::string> parameter_names() const;
  /// Throws InvalidArgument, naming `context` (e.g. "simulate_rtest: truth"), if the effect
  /// parameter count does not match the effects, a value is not finite, or an effect does not
  /// exist on this machine.
  void validate(const std::string& context) const;
};

}  // namespace rotacal
