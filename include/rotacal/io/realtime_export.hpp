// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A fitted model as the controller's real-time path holds it (realtime/model.hpp): what
/// `rotacal export --controller realtime` writes as a blob (realtime/blob.hpp), and the library's
/// side of reading one back. The real-time headers need nothing of this file.

#include <cstdint>
#include <string>
#include <vector>

#include "rotacal/io/model_file.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/realtime/model.hpp"

namespace rotacal {

struct ThermalModel;  // io/thermal_model.hpp

/// The real-time model of a machine with location errors e and effects fx (parameters p):
/// the machine's axes, pivot length, errors, effects and a_ref (zero when unset, as the
/// evaluators take it). Thermal gains are zero (a thermal model: the overload below). Throws
/// InvalidArgument naming `context` when the model does not fit the fixed capacity
/// (realtime::kMaxEffects, kMaxParams), an effect does not apply to the machine, or the
/// parameter count does not match.
realtime::Model realtime_model(MachineType m, const LocationErrors<double>& e,
                               const EffectModel& fx, const std::vector<double>& p,
                               const std::string& context);
/// The same from a model file (its location errors, effects and parameters).
realtime::Model realtime_model(const ModelFile& model, const std::string& context);

/// The real-time model of a thermal model (io/thermal_model.hpp): its cold location errors and,
/// per lag, its gains as the blob's thermal_gain columns (y1, y2 come from the controller, which
/// runs the lags: the LinuxCNC HAL chain). A gain the test could not determine is 0 in the
/// model file and here. No effects: a thermal model holds none.
realtime::Model realtime_model(const ThermalModel& model, const std::string& context);

/// The fingerprint (realtime::machine_fingerprint) of a machine's nominal kinematics.
std::uint64_t realtime_fingerprint(MachineType m);

/// Reads a blob for machine m (any machine when m is not given); throws ParseError naming
/// `source`, the field and why when realtime::decode refuses it.
realtime::Model read_realtime_blob(const std::string& bytes, const MachineType* m,
                                   const std::string& source);

}  // namespace rotacal
