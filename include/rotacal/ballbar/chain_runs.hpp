// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The runs of the measure -> compensate -> measure-again experiment (Flynn et al. 2016,
/// Sec. 4), simulated: a run plays the planned test (nominal, or compensated for location
/// errors identified before) on a machine, records it with AR(1) reading noise against the
/// nominal program (as ballbar software holding that program does) and identifies the 8
/// location errors again. `identify_runs` does a batch of runs in one call, so that Monte
/// Carlo draws and the responses of many causes stay in C++; the analysis that composes them
/// (draws, causes, fits) is Python's (rotacal.flynn_table2).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/ballbar/model.hpp"
#include "rotacal/ballbar/plan.hpp"

namespace rotacal {

struct ChainRunOptions {
  /// Identification of every run: "paper" (identify_paper, as Flynn et al.) or "joint"
  /// (identify_joint with noise "auto", rotacal.ballbar.identify's default).
  std::string method = "paper";
  double noise_um = 0.5;   ///< marginal 1-sigma of the reading noise, um; declared in each record
  double noise_rho = 0.0;  ///< AR(1) correlation of successive readings of a test
};

using LocationErrorRows = Eigen::Matrix<double, Eigen::Dynamic, 8, Eigen::RowMajor>;

/// The session a run records: `program` (a commanded session, e.g. a compensated plan) played
/// on `machine`, each reading plus AR(1) noise of options.noise_um and options.noise_rho per
/// test in time order (noise_gen::ar1 with `seed`; none without a seed), recorded against
/// `nominal`: the nominal X,Y,Z and pivot, the program's tests, times and angles.
/// Throws InvalidArgument if the sample counts or the machines differ (simulate_ballbar,
/// make_ballbar_session).
BallbarSession record_run(const BallbarSession& nominal, const BallbarSession& program,
                          const BallbarMachineModel& machine, std::optional<std::uint64_t> seed,
                          const ChainRunOptions& options = {});

/// Location errors identified from one run on each of `machines` (row i: machines[i], in
/// location_error_names order). Run i plays the test planned by `setup`, compensated for row i
/// of `compensate_for` (no rows: the nominal test on every machine), recorded with noise
/// seeds[i] (`seeds` empty: noise-free). Throws InvalidArgument if `compensate_for` or `seeds`
/// has neither 0 nor machines.size() rows, or the method is unknown.
LocationErrorRows identify_runs(const BallbarSetup& setup,
                                const std::vector<BallbarMachineModel>& machines,
                                const LocationErrorRows& compensate_for,
                                const std::vector<std::uint64_t>& seeds,
                                const ChainRunOptions& options = {});

}  // namespace rotacal
