// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A joint R-test identification as a `rotacal-model/1` document of kind "rtest-joint": what
/// `rotacal identify --save-model` writes for an R-test session, so that a C++ program that
/// identified a machine writes the same file as the command line:
///
///     write_model(rtest_joint_model_document(identification, session.nests), "model.json");
///
/// The layout of the file is io/model_file.hpp's (RtestJointModelContent); this header only
/// takes an identification apart into it.

#include <Eigen/Core>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "rotacal/io/model_file.hpp"
#include "rotacal/rtest/identify_joint.hpp"

namespace rotacal {

/// The model file's content of a joint identification; `nests` as the session names them.
/// InvalidArgument if a parameter of the model (or a set-up's probe zero) is missing from
/// `identification.parameters`.
RtestJointModelContent rtest_joint_model_content(
    const RtestJointIdentification& identification,
    const std::map<std::string, Eigen::Vector3d>& nests);

/// rtest_joint_model_document(rtest_joint_model_content(identification, nests)).
nlohmann::ordered_json rtest_joint_model_document(
    const RtestJointIdentification& identification,
    const std::map<std::string, Eigen::Vector3d>& nests);

}  // namespace rotacal
