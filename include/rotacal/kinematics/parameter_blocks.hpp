// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The parameter blocks every instrument's problem shares (core/parameter_layout.hpp): the 8
/// location errors of the machine, and the parameters of an effect model, with the names and
/// units the fits report.

#include <string>
#include <vector>

#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

/// Block "location_errors": the 8 location errors of m in location_error_names(m) order
/// (mm for positions, rad for directions).
inline ParameterBlock add_location_errors(ParameterLayout& layout, MachineType m) {
  std::vector<std::string> names, units;
  for (int k = 0; k < 8; ++k) {
    names.push_back(location_error_names(m)[static_cast<std::size_t>(k)]);
    units.push_back(location_error_is_angle(k) ? "rad" : "mm");
  }
  return layout.add("location_errors", std::move(names), std::move(units));
}

/// The name of parameter k of effect f in a fit: the effect's id alone when it has one
/// parameter, else "<id>.<parameter>".
inline std::string effect_parameter_name(const Effect& f, std::size_t k) {
  const std::vector<std::string> pn = f.param_names();
  return f.id() + (pn.size() > 1 ? "." + pn[k] : "");
}

/// Block `name` (default "effects"): the parameters of fx in EffectModel order (the
/// `fx_params` array of the kinematics), named by effect_parameter_name.
inline ParameterBlock add_effects(ParameterLayout& layout, const EffectModel& fx,
                                  const std::string& name = "effects") {
  std::vector<std::string> names, units;
  for (const Effect& f : fx.effects) {
    const std::vector<std::string> pu = f.param_units();
    for (std::size_t k = 0; k < pu.size(); ++k) {
      names.push_back(effect_parameter_name(f, k));
      units.push_back(pu[k]);
    }
  }
  return layout.add(name, std::move(names), std::move(units));
}

/// The parameters of effect i of fx within its block `effects` (add_effects), named by the
/// effect's id.
inline ParameterBlock effect_block(const ParameterBlock& effects, const EffectModel& fx,
                                   std::size_t i) {
  return effects.part(fx.offset(i), fx.effects[i].num_params(), fx.effects[i].id());
}

}  // namespace rotacal
