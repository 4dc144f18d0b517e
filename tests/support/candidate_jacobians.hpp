// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Test support: the candidate Jacobians of a diagnosis problem (the harmonic shortcut of
// src/diagnose/candidate_jets.hpp) against Jets of every parameter of each candidate.
#include <algorithm>
#include <catch2/catch.hpp>
#include <vector>

#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal::synthetic {

/// At the fit of model `fx`, every candidate the model does not hold; returns how many of them
/// are harmonic.
template <typename Problem>
int check_candidate_jacobians(const Problem& P, const EffectModel& fx) {
  const ModelFit at = P.fit(fx);
  std::vector<Effect> candidates;
  for (const Effect& c : P.candidates(4))
    if (std::find(fx.effects.begin(), fx.effects.end(), c) == fx.effects.end())
      candidates.push_back(c);
  const std::vector<Eigen::MatrixXd> batch = P.candidate_jacobians(at, candidates);
  REQUIRE(batch.size() == candidates.size());
  int harmonic = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    INFO(candidates[i].id());
    const Eigen::MatrixXd jets = P.candidate_jacobian_by_jets(at, candidates[i]);
    REQUIRE(batch[i].rows() == jets.rows());
    REQUIRE(batch[i].cols() == jets.cols());
    const double scale = jets.cwiseAbs().maxCoeff();
    REQUIRE(scale > 0.0);
    // 1e-10 of the column's size: the chain rule sums in another order than the Jets. Under
    // clang -O1 (the sanitizer build) servo_lag_B on BC-trt differed by 1.4e-12 of its size, where
    // GCC -O3 stays under 1e-12; a wrong factor (1e-4 of one stage's sensitivity) is far above.
    CHECK((batch[i] - jets).cwiseAbs().maxCoeff() <= 1e-10 * scale);
    CHECK((P.candidate_jacobian(at, candidates[i]) - jets).cwiseAbs().maxCoeff() <= 1e-10 * scale);
    harmonic += candidates[i].is_harmonic();
  }
  return harmonic;
}

}  // namespace rotacal::synthetic
