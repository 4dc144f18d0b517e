// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A virtual machine with a ballbar: the exact reading for each commanded sample, plus
/// Gaussian noise. The analysis never sees the model it was made with.

#include <cstdint>

#include "rotacal/ballbar/model.hpp"

namespace rotacal {

struct BallbarSimulationOptions {
  double noise_um = 0.5;      ///< 1-sigma Gaussian noise of one reading, um
  std::uint64_t seed = 1;     ///< random seed (same seed, same file)
  bool declare_noise = true;  ///< write `# noise_um:` into the session
};

/// Fill in `length` of every sample of `commanded` (test labels, time, X,Y,Z, rotary angles;
/// its ballbar_length and nominal pivot are kept) as the machine `truth` would measure it.
/// Throws InvalidArgument if the model's machine differs from the session's, if the effect
/// parameter count is wrong, or if noise_um is negative or not finite.
BallbarSession simulate_ballbar(const BallbarSession& commanded, const BallbarMachineModel& truth,
                                const BallbarSimulationOptions& options = {});

}  // namespace rotacal
