// SPDX-License-Identifier: BSD-3-Clause
// A ballbar machine model in and out of a rotacal-model/1 document (ballbar/model_document.hpp).
#include "rotacal/ballbar/model_document.hpp"

#include <string>

#include "rotacal/core/error.hpp"

namespace rotacal {

using json = nlohmann::ordered_json;

json ballbar_model_document(const BallbarMachineModel& model) {
  json doc = model_document_header("ballbar", model.machine);
  json le = json::object();
  const auto& names = location_error_names(model.machine);
  for (int k = 0; k < 8; ++k)
    le[names[k]] = {{"value", model.errors.v[k]},
                    {"unit", location_error_is_angle(k) ? "rad" : "mm"}};
  doc["location_errors"] = le;
  doc["pivot"] = json::object();
  for (int a = 0; a < 3; ++a)
    doc["pivot"][std::string(1, "xyz"[a])] = {{"value", model.pivot[a]}, {"unit", "mm"}};
  json fx = json::array();
  std::size_t offset = 0;
  for (const Effect& e : model.effects.effects) {
    json params = json::object();
    const auto pn = e.param_names();
    const auto pu = e.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k) {
      if (offset >= model.effect_params.size())
        throw InvalidArgument(
            "ballbar_model_document: effect_params has fewer values than the effects need");
      params[pn[k]] = {{"value", model.effect_params[offset++]}, {"unit", pu[k]}};
    }
    fx.push_back({{"id", e.id()}, {"cause", e.cause()}, {"params", params}});
  }
  doc["effects"] = fx;
  return doc;
}

BallbarMachineModel ballbar_machine_model(const ModelFile& model) {
  if (model.kind != "ballbar" || !model.pivot)
    throw InvalidArgument("ballbar_machine_model: a " + model.kind +
                          " model is not a ballbar model");
  BallbarMachineModel m;
  m.machine = model.machine;
  m.errors = model.location_errors;
  m.pivot = *model.pivot;
  m.effects = model.effects;
  m.effect_params = model.effect_params;
  return m;
}

}  // namespace rotacal
