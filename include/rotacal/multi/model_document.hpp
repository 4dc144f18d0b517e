// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// One identification from several sessions (multi/identify.hpp) as a `rotacal-model/1`
/// document of kind "multi": what `rotacal identify S1 S2 ... --save-model` writes, so that a
/// C++ program that identified a machine jointly writes the same file as the command line:
///
///     write_model(multi_model_document(identification), "model.json");
///
/// The layout of the file is io/fitted_model.hpp's; this header only takes an identification
/// apart into it.

#include <nlohmann/json.hpp>

#include "rotacal/io/fitted_model.hpp"
#include "rotacal/multi/identify.hpp"

namespace rotacal {

/// The model file's content of a joint identification of several sessions: the shared location
/// errors and effects, the joint covariance (the sessions' own parameters as
/// "<session>:<name>"), each session with its own parameters, its location errors alone, its
/// noise model, and the disagreements. InvalidArgument when the covariance does not match
/// `parameter_names` or the effects' parameters do not match the effect model, and when the
/// sessions disagree (refuse_disagreeing).
FittedModelContent multi_model_content(const MultiIdentification& identification);

/// InvalidArgument naming every disagreement (parameter, sessions, z) unless there is none or
/// the sigmas were widened for them (MultiFitOptions::inflate_sigma): no model is kept of
/// sessions that disagree.
void refuse_disagreeing(const MultiIdentification& identification);

/// fitted_model_document(multi_model_content(identification)).
nlohmann::ordered_json multi_model_document(const MultiIdentification& identification);

}  // namespace rotacal
