// SPDX-License-Identifier: BSD-3-Clause
// The parts of the Monte Carlo checks that both instruments share: noise draws and the summary.
#include "rotacal/core/monte_carlo.hpp"

#include <cmath>
#include <limits>
#include <random>

#include "rotacal/core/noise_handling.hpp"

namespace rotacal {

Eigen::VectorXd monte_carlo_noise(bool coloured, const NoiseModel& model, double sigma_um,
                                  Eigen::Index n, std::uint64_t seed, int k) {
  std::mt19937_64 rng(seed + static_cast<std::uint64_t>(k));
  if (coloured) return draw_noise(model, rng);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
  if (sigma_um <= 0.0) return e;
  std::normal_distribution<double> g(0.0, sigma_um * 1e-3);
  for (Eigen::Index i = 0; i < n; ++i) e[i] = g(rng);
  return e;
}

std::vector<MonteCarloParameter> monte_carlo_summary(
    const std::vector<ParameterEstimate>& estimates, const Eigen::MatrixXd& values,
    const std::function<bool(const ParameterEstimate&)>& skip) {
  std::vector<MonteCarloParameter> out;
  const Eigen::Index draws = values.rows();
  for (std::size_t j = 0; j < estimates.size(); ++j) {
    const ParameterEstimate& e = estimates[j];
    if (!e.observable || (skip && skip(e))) continue;
    const Eigen::VectorXd v = values.col(static_cast<Eigen::Index>(j));
    const double mean = v.mean();
    MonteCarloParameter m;
    m.name = e.name;
    m.unit = e.unit;
    m.std_reported = e.std;
    m.std_mc = std::sqrt((v.array() - mean).square().sum() / static_cast<double>(draws - 1));
    m.ratio = e.std > 0 ? m.std_mc / e.std : std::numeric_limits<double>::infinity();
    m.bias = mean - e.value;
    out.push_back(m);
  }
  return out;
}

}  // namespace rotacal
