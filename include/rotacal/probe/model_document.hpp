// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A touch-probe identification (the joint fit, probe/identify.hpp) as a `rotacal-model/1`
/// document of kind "probe": what `rotacal identify PROBE.csv --save-model` writes, so that a
/// C++ program that identified a machine writes the same file as the command line:
///
///     write_model(probe_model_document(identification, "probe.csv"), "model.json");
///
/// The layout of the file is io/fitted_model.hpp's; this header only takes an identification
/// apart into it.

#include <nlohmann/json.hpp>
#include <string>

#include "rotacal/io/fitted_model.hpp"
#include "rotacal/probe/identify.hpp"

namespace rotacal {

/// The model file's content of a joint probe fit; `session_name` names the session (its file).
/// The location errors and effect parameters are the fit's, every other parameter (sphere.x/y/z,
/// tool_offset_Z on a machine with head axes) the session's own. InvalidArgument for a fit of the
/// cycles' method (no uncertainty, no covariance) or one that lacks a parameter of its model.
FittedModelContent probe_model_content(const ProbeIdentification& identification,
                                       const std::string& session_name);

/// fitted_model_document(probe_model_content(identification, session_name)).
nlohmann::ordered_json probe_model_document(const ProbeIdentification& identification,
                                            const std::string& session_name);

}  // namespace rotacal
