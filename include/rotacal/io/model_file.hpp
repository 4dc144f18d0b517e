// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Fitted machine models as `rotacal-model/1` JSON files (docs/model_file.md): the one reader
/// and writer behind `rotacal identify --save-model`, `rotacal predict`/`compensate` and the
/// Python `rotacal.save_model`/`load_model`, so a CNC vendor linking the C++ library reads
/// exactly what the command line wrote.
///
/// The reader validates every member a model is used through (format and its version, kind,
/// machine, the eight location errors with their units, pivot, effects and their parameters,
/// the R-test basis) and keeps the whole document, so kind-specific members (covariance,
/// nests, fit summary) survive a read/write round trip. JSON out is strict: a non-finite
/// number is written as null and its JSON pointer listed in "null_reasons" with why.

#include <array>
#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/io/output_file.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

/// The format this library writes, and the major version it reads (minor versions only add
/// members, which a reader ignores).
inline constexpr const char* kModelFormat = "rotacal-model/1";
inline constexpr int kModelFormatMajor = 1;

/// Largest model file read (bytes): a model is a few hundred kB at most (a covariance of 200
/// parameters is 1 MB); with the bounds of core/json_text.hpp it parses within ~0.5 GB.
inline constexpr std::size_t kMaxModelFileBytes = 16u << 20;

/// Limits on a model's values beyond which it cannot describe a machine tool (a typo, wrong
/// units, or a broken fit): position errors mm, orientation errors rad, pivot mm.
inline constexpr double kMaxModelPositionError = 100.0;
inline constexpr double kMaxModelAngleError = 0.5;
inline constexpr double kMaxModelPivot = 1.0e4;

/// A validated model file.
struct ModelFile {
  int format_minor = 0;  ///< N of rotacal-model/1.N (0 for "rotacal-model/1")
  std::string kind;      ///< "ballbar", "rtest-joint", "rtest-diagnosis", "probe" or "multi"
                         ///< (io/fitted_model.hpp)
  MachineType machine = MachineType::AC_trt;
  /// Location errors in location_error_names(machine) order (mm, rad); an unobservable one
  /// (value null) is nominal, 0, and flagged in `observable`.
  LocationErrors<double> location_errors;
  std::array<bool, 8> observable{};
  std::optional<Eigen::Vector3d> pivot;  ///< table frame, mm (ballbar models)
  EffectModel effects;
  std::vector<double> effect_params;  ///< effects.num_params() values, nulls as 0
  nlohmann::ordered_json document;    ///< the whole file as read (strict, no NaN)
};

/// Validate a parsed document; `source` names the file in messages. Throws InvalidArgument
/// "source: member: what is wrong".
ModelFile model_from_json(const nlohmann::ordered_json& document, const std::string& source);
/// Parse model-file text; a JSON syntax error names source, line and column.
ModelFile parse_model(const std::string& text, const std::string& source);
/// Read a model file; IoError if it cannot be read (a directory, missing, too large).
ModelFile read_model(const std::string& path);
/// Read a model file checking what every use needs (strict JSON, format version, kind, machine; all
/// of a probe or multi model); other kinds' members are checked where used (model_from_json).
nlohmann::ordered_json read_model_document(const std::string& path);

/// Replace every non-finite number by null and record why under "null_reasons"
/// (JSON pointer -> "NaN" / "+Infinity" / "-Infinity" and what that means).
nlohmann::ordered_json strict_json(nlohmann::ordered_json document);
/// The file text of a model document: validated (throws InvalidArgument naming "source" like
/// the reader would, so nothing is written that cannot be read back), strict, 2-space indented.
std::string format_model(const nlohmann::ordered_json& document,
                         const std::string& source = "model");
/// format_model, then written by the output rule (rotacal/io/output_file.hpp).
void write_model(const nlohmann::ordered_json& document, const std::string& path,
                 const OutputOptions& options = {});

/// The members every model document starts with: format, kind, machine (and the description of
/// a machine that is not a built-in table-table one). The instruments' writers
/// (ballbar/model_document.hpp, rtest/model_document.hpp) add their own members to it.
nlohmann::ordered_json model_document_header(const std::string& kind, MachineType machine);

/// What a "rtest-joint" model file holds (docs/model_file.md), in plain values: the joint
/// R-test identification (rtest/identify_joint.hpp) as the file writes it. rtest/model_document.hpp
/// fills it from an identification.
struct RtestJointModelContent {
  MachineType machine = MachineType::BC_trt;
  int b_degree = 0, c_harmonics = 0, c_b_degree = 0;  ///< the basis (RtestBasis)
  bool gamma_cb = false;
  /// In model order: the 8 location errors, "tool_offset_Z" on a machine with head axes, the
  /// map coefficients. An unobservable one keeps the value the fit gave it under its convention
  /// (written with "observable": false and no std), so that the file predicts as the fit did.
  std::vector<ParameterEstimate> parameters;
  Eigen::MatrixXd covariance;                    ///< of `parameters`, mm and rad
  std::map<std::string, Eigen::Vector3d> nests;  ///< nominal ball centre per nest, table frame, mm
  std::map<std::string, std::array<ParameterEstimate, 3>> probe_zeros;  ///< x, y, z per set-up, mm
  double residual_rms_um = 0.0;
  double sigma_um = 0.0;
  std::size_t n_samples = 0;
  bool converged = false;
  std::vector<std::string> unobservable;  ///< combinations the nests cannot see, in words
  std::vector<std::string> notes;
};

/// The document of an R-test joint model (kind "rtest-joint"): basis with its definition,
/// location errors, tool_offset_Z on a machine with head axes, map coefficients, covariance,
/// nests, probe zeros and the fit's summary. InvalidArgument when the parameters or the
/// covariance do not match the machine (fewer than its location errors, a wrong size).
nlohmann::ordered_json rtest_joint_model_document(const RtestJointModelContent& content);

}  // namespace rotacal
