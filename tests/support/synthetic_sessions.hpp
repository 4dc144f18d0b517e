// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Synthetic machines and sessions that several tests and benchmarks build alike: the
/// commanded rows of the shared Table 2 session, random machines with plausible location
/// errors, the R-test truth of ../shared/data/rtest_bc_oyama.truth.json, and ballbar sessions
/// with coloured noise added to the readings as a recorder would see it.
/// Needs ROTACAL_SHARED_DIR (set by tests/CMakeLists.txt and bench/CMakeLists.txt).

#include <Eigen/Core>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/kinematics/machine_model.hpp"

namespace rotacal::synthetic {

inline std::string shared_file(const std::string& relative) {
  return std::string(ROTACAL_SHARED_DIR) + "/" + relative;
}

/// The commanded rows of the independent implementation's complete single set-up test.
inline const BallbarSession& table2_commanded() {
  static const BallbarSession s = read_ballbar(shared_file("data/ballbar_ac_table2.csv"));
  return s;
}

/// A machine of the session's kinematics with location errors of 30 um and 50 urad (1 sigma)
/// and a pivot set up 20 um (1 sigma per axis) away from the commanded one.
inline BallbarMachineModel random_ballbar_machine(const BallbarSession& cmd, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  BallbarMachineModel m;
  m.machine = cmd.machine;
  for (int i = 0; i < 8; ++i)
    m.errors.v[i] = location_error_is_angle(i) ? 5e-5 * N(rng) : 0.03 * N(rng);
  m.pivot = cmd.pivot + Eigen::Vector3d(N(rng), N(rng), N(rng)) * 0.02;
  return m;
}

/// A B/C table with location errors of 20 um and 30 urad (1 sigma).
inline MachineModel random_bc_table(std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  MachineModel t = MachineModel::nominal(MachineType::BC_trt);
  for (int i = 0; i < 8; ++i)
    t.errors.v[i] = location_error_is_angle(i) ? 3e-5 * N(rng) : 0.02 * N(rng);
  return t;
}

/// The machine of ../shared/data/rtest_bc_oyama.truth.json (location errors, gravity sag and
/// coning of B), read from the file.
inline MachineModel oyama_truth() {
  std::ifstream in(shared_file("data/rtest_bc_oyama.truth.json"));
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);  // effects in file order
  MachineModel t = MachineModel::nominal(MachineType::BC_trt);
  const auto& names = location_error_names(t.machine);
  for (std::size_t i = 0; i < names.size(); ++i)
    t.errors.v[static_cast<Eigen::Index>(i)] = j.at("errors").at(names[i]);
  for (const auto& [id, value] : j.at("effects").items()) {
    t.effects.effects.push_back(Effect::parse(id));
    t.effect_params.push_back(value.get<double>());
  }
  return t;
}

/// Noise (mm) for every sample of a ballbar session, per test as recorded: rho < 0 1/f-like,
/// rho == 0 white, else AR(1) with that coefficient; marginal sigma sigma_mm.
inline Eigen::VectorXd coloured_length_noise(const BallbarSession& s, double rho, double sigma_mm,
                                             std::uint64_t seed) {
  std::vector<std::string> g;
  std::vector<double> t;
  for (const BallbarSample& x : s.samples) g.push_back(x.test), t.push_back(x.time);
  return rho < 0 ? noise_gen::pink(g, t, sigma_mm, seed)
                 : noise_gen::ar1(g, t, rho, sigma_mm, seed);
}

/// A noise-free simulation of `cmd` on `truth` plus coloured noise (coloured_length_noise) of
/// marginal sigma noise_um, which the file declares, as a user who measured the noise at rest
/// would.
inline BallbarSession noisy_ballbar(const BallbarSession& cmd, const BallbarMachineModel& truth,
                                    double rho, double noise_um, std::uint64_t seed) {
  BallbarSession s = simulate_ballbar(cmd, truth, {0.0, 1, false});
  const Eigen::VectorXd e = coloured_length_noise(s, rho, noise_um * 1e-3, seed);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    s.samples[i].length += e[static_cast<Eigen::Index>(i)];
  s.noise_um = noise_um;
  return s;
}

}  // namespace rotacal::synthetic
