// SPDX-License-Identifier: BSD-3-Clause
// Ballbar simulator: predicted lengths on a machine model plus Gaussian noise.
#include "rotacal/ballbar/simulate.hpp"

#include <cmath>
#include <random>

namespace rotacal {

std::vector<double> predict_lengths(const BallbarMachineModel& model,
                                    const std::vector<BallbarSample>& samples) {
  if (static_cast<int>(model.effect_params.size()) != model.effects.num_params())
    throw InvalidArgument("effect_params: expected " + std::to_string(model.effects.num_params()) +
                          " values for the model's effects, got " +
                          std::to_string(model.effect_params.size()));
  const std::vector<RotaryMotion> motion = rotary_motion(samples);
  const EffectModel fx = centred_on(model.effects, samples);  // unset a_ref: these samples' mean
  std::vector<double> out;
  out.reserve(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i)
    out.push_back(predicted_length<double>(model.machine, model.errors, model.pivot, fx,
                                           model.effect_params.data(), samples[i], motion[i]));
  return out;
}

BallbarSession simulate_ballbar(const BallbarSession& commanded, const BallbarMachineModel& truth,
                                const BallbarSimulationOptions& options) {
  if (truth.machine != commanded.machine)
    throw InvalidArgument("simulate_ballbar: model is for " + to_string(truth.machine) +
                          " but the session is for " + to_string(commanded.machine));
  if (!(options.noise_um >= 0.0) || !std::isfinite(options.noise_um))
    throw InvalidArgument("noise_um must be finite and >= 0");
  for (const Effect& f : truth.effects.effects)
    if (!f.applies_to(truth.machine))
      throw InvalidArgument("effect " + f.id() + " does not exist on a " +
                            to_string(truth.machine));
  BallbarSession out = commanded;
  const std::vector<double> L =
      predict_lengths(truth, commanded.samples);  // about the session's mean
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, options.noise_um * 1e-3);
  for (std::size_t i = 0; i < L.size(); ++i)
    out.samples[i].length = L[i] + (options.noise_um > 0 ? noise(rng) : 0.0);
  // A noiseless simulation declares no noise: a 1-sigma of 0 would give each reading infinite
  // weight, and the session readers refuse it (the fit then takes the residuals' scatter).
  if (options.declare_noise && options.noise_um > 0.0) {
    out.noise_um = options.noise_um;
    bool found = false;
    for (auto& kv : out.metadata)
      if (kv.first == "noise_um") kv.second = std::to_string(options.noise_um), found = true;
    if (!found) out.metadata.emplace_back("noise_um", std::to_string(options.noise_um));
  }
  return out;
}

}  // namespace rotacal
