// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The errors that move with each table axis of a model file, as functions of the axis' angle
/// (the terms of io/angle_map.hpp): the source of every controller's compensation table. Above
/// the instruments, because an R-test joint model is evaluated by the R-test error model.

#include <string>
#include <vector>

#include "rotacal/io/angle_map.hpp"
#include "rotacal/io/model_file.hpp"

namespace rotacal {

/// The function of every table-side rotary axis of the model's machine, in chain order. An
/// axis on the head is not covered: it is named in the result's notes. Throws InvalidArgument
/// naming `source` and the member when an R-test model's map is not the basis' own.
std::vector<AxisErrorFunction> axis_error_functions(const ModelFile& model,
                                                    const std::string& source);

}  // namespace rotacal
