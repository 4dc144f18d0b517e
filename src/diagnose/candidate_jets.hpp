// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: candidate Jacobians by Jets of the instrument's one model, shared
// by the ballbar and R-test problems.
//
// Two savings over Jets of width 4 for every candidate, which were 85 % of a diagnosis and its
// budget (perf, ballbar_ac_table2.csv): Jets only as wide as the parameters seeded (a Jet costs
// about N + 1 doubles), and one evaluation per harmonic kind and axis for all its orders
// (Effect::is_harmonic: column 2j is the order-0 channel j times cos(nR), column 2j + 1 times
// sin(nR)). Diagnosis + budget of ballbar_ac_table2.csv: 78 + 66 ms -> 42 + 30 ms.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/effects.hpp"

namespace rotacal::diagnosis_detail {

/// `jets(std::integral_constant<int, N>{}, effect, seed)` with N = seed.size() (1 to 4): the
/// instrument's d reading / d (the seeded parameters of `effect`), one column per seed.
template <typename Jets>
Eigen::MatrixXd jets_of_width(const Effect& effect, const std::vector<int>& seed, Jets&& jets) {
  switch (seed.size()) {
    case 1:
      return jets(std::integral_constant<int, 1>{}, effect, seed);
    case 2:
      return jets(std::integral_constant<int, 2>{}, effect, seed);
    case 3:
      return jets(std::integral_constant<int, 3>{}, effect, seed);
    case 4:
      return jets(std::integral_constant<int, 4>{}, effect, seed);
    default:
      break;
  }
  throw InvalidArgument("candidate " + effect.id() + " has " + std::to_string(seed.size()) +
                        " parameters; the diagnosis handles 1 to 4");
}

inline std::vector<int> all_parameters(const Effect& c) {
  std::vector<int> seed(static_cast<std::size_t>(c.num_params()));
  for (std::size_t k = 0; k < seed.size(); ++k) seed[k] = static_cast<int>(k);
  return seed;
}

/// The order-0 channels of a harmonic candidate: Jets seeded on its cos parameters.
template <typename Jets>
Eigen::MatrixXd harmonic_channels(const Effect& candidate, Jets&& jets) {
  Effect order0 = candidate;
  order0.harmonic = 0;
  std::vector<int> seed;
  for (int j = 0; 2 * j < candidate.num_params(); ++j) seed.push_back(2 * j);
  return jets_of_width(order0, seed, jets);
}

/// A harmonic candidate's Jacobian from its channels G; `angles_of_row(r)` are the commanded
/// angles of row r.
template <typename AnglesOfRow>
Eigen::MatrixXd expand_harmonic(MachineType m, const Effect& candidate, const Eigen::MatrixXd& G,
                                AnglesOfRow&& angles_of_row) {
  Eigen::MatrixXd out(G.rows(), candidate.num_params());
  for (Eigen::Index r = 0; r < G.rows(); ++r) {
    const double nR = harmonic_angle(m, candidate, angles_of_row(r));
    const double c = std::cos(nR), s = std::sin(nR);
    for (Eigen::Index j = 0; j < G.cols(); ++j) {
      out(r, 2 * j) = G(r, j) * c;
      out(r, 2 * j + 1) = G(r, j) * s;
    }
  }
  return out;
}

/// Each candidate's Jacobian at one fit handed to `visit(index, jacobian)` in order, the
/// channels of each harmonic kind and axis evaluated once; only the channels are kept.
template <typename Jets, typename AnglesOfRow, typename Visit>
void for_each_candidate(MachineType m, const std::vector<Effect>& candidates, Jets&& jets,
                        AnglesOfRow&& angles_of_row, Visit&& visit) {
  std::vector<std::pair<Effect, Eigen::MatrixXd>> channels;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Effect& c = candidates[i];
    if (!c.is_harmonic()) {
      visit(i, jets_of_width(c, all_parameters(c), jets));
      continue;
    }
    Effect key = c;
    key.harmonic = 0;
    auto it = std::find_if(channels.begin(), channels.end(),
                           [&](const auto& e) { return e.first == key; });
    if (it == channels.end()) {
      channels.emplace_back(key, harmonic_channels(c, jets));
      it = channels.end() - 1;
    }
    visit(i, expand_harmonic(m, c, it->second, angles_of_row));
  }
}

/// Jacobians of every candidate at one fit (for_each_candidate, all kept).
template <typename Jets, typename AnglesOfRow>
std::vector<Eigen::MatrixXd> jacobians_of_candidates(MachineType m,
                                                     const std::vector<Effect>& candidates,
                                                     Jets&& jets, AnglesOfRow&& angles_of_row) {
  std::vector<Eigen::MatrixXd> out;
  out.reserve(candidates.size());
  for_each_candidate(m, candidates, jets, angles_of_row,
                     [&](std::size_t, Eigen::MatrixXd&& J) { out.push_back(std::move(J)); });
  return out;
}

/// One candidate's Jacobian (its own channels when harmonic).
template <typename Jets, typename AnglesOfRow>
Eigen::MatrixXd jacobian_of_candidate(MachineType m, const Effect& c, Jets&& jets,
                                      AnglesOfRow&& angles_of_row) {
  if (!c.is_harmonic()) return jets_of_width(c, all_parameters(c), jets);
  return expand_harmonic(m, c, harmonic_channels(c, jets), angles_of_row);
}

}  // namespace rotacal::diagnosis_detail
