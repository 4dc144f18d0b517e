// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A ballbar machine model as a `rotacal-model/1` document of kind "ballbar", and back: what a
/// C++ program that fitted or edited a model writes, and what `rotacal predict`/`compensate`
/// read. The file's layout and its reader are io/model_file.hpp's; this header only puts a
/// BallbarMachineModel into it and takes it out, so that io/ stays below the instruments.
///
///     write_model(ballbar_model_document(model), "model.json");
///     const BallbarMachineModel m = ballbar_machine_model(read_model("model.json"));

#include <nlohmann/json.hpp>

#include "rotacal/ballbar/model.hpp"
#include "rotacal/io/model_file.hpp"

namespace rotacal {

/// The document of a ballbar model with the given values (no uncertainties).
nlohmann::ordered_json ballbar_model_document(const BallbarMachineModel& model);
/// The machine model of a "ballbar" model file (InvalidArgument for other kinds).
BallbarMachineModel ballbar_machine_model(const ModelFile& model);

}  // namespace rotacal
