// SPDX-License-Identifier: BSD-3-Clause
// MachineModel: parameter names and validation shared by the ballbar and the R-test.
#include "rotacal/kinematics/machine_model.hpp"

#include <cmath>

namespace rotacal {

std::vector<std::string> MachineModel::parameter_names() const {
  std::vector<std::string> out(location_error_names(machine).begin(),
                               location_error_names(machine).end());
  for (const std::string& l : effects.param_labels()) out.push_back(l);
  return out;
}

void MachineModel::validate(const std::string& context) const {
  if (static_cast<int>(effect_params.size()) != effects.num_params())
    throw InvalidArgument(context + ".effect_params: " + std::to_string(effect_params.size()) +
                          " values for an effect model of " + std::to_string(effects.num_params()) +
                          " parameters");
  for (int k = 0; k < 8; ++k)
    if (!std::isfinite(errors.v[k]))
      throw InvalidArgument(
          context + ".errors: " + location_error_names(machine)[static_cast<std::size_t>(k)] +
          " is not finite");
  for (std::size_t k = 0; k < effect_params.size(); ++k)
    if (!std::isfinite(effect_params[k]))
      throw InvalidArgument(context + ".effect_params[" + std::to_string(k) + "] is not finite");
  for (const Effect& f : effects.effects)
    if (!f.applies_to(machine))
      throw InvalidArgument(context + ".effects: " + f.id() + " does not exist on a " +
                            to_string(machine));
}

}  // namespace rotacal
