// SPDX-License-Identifier: BSD-3-Clause
// One session of a multi-session fit as the stacked model needs it (multi/identify.hpp): the
// instrument's own residual model, its unknowns with their start values, where its location
// errors lie in its own vector, and its noise streams. Private to src/multi.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/multi/identify.hpp"

namespace rotacal::multi_detail {

struct SessionPart {
  std::string name, instrument;
  std::shared_ptr<const void> data;      // arrays the model refers to (kept alive)
  std::unique_ptr<ResidualModel> model;  // the instrument's residual model
  std::vector<FitParameter> parameters;  // its unknowns, its own vector order
  Eigen::Index errors_offset = 0;        // its location-error block
  Eigen::Index errors_size = 0;
  // Per parameter: its index among the shared ones (the location errors, then the shared
  // effects' parameters, by name), or -1 for the session's own.
  std::vector<Eigen::Index> shared;
  JointFitSettings settings;        // sigma of the declared noise
  std::vector<std::string> groups;  // noise stream of every residual
  std::vector<double> times;        // time (s) of every residual
  bool allow_reml = false;          // the R-test's wandering zeros (rtest/identify_joint.cpp)
  OwnNoiseModel own_noise;          // the touch probe's (probe/touch_noise.hpp)
};

/// The part of one session with the shared catalogue effects `fx` fitted along (their
/// linear-axis polynomials about fx's linear_reference: set by the caller, the same for every
/// session). Throws InvalidArgument (naming the session) for a session without data or an
/// effect its instrument does not model on its machine.
SessionPart session_part(const MultiSessionInput& input, const EffectModel& fx);

}  // namespace rotacal::multi_detail
