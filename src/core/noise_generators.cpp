// SPDX-License-Identifier: BSD-3-Clause
// Seeded coloured-noise generators (noise_model.hpp, noise_gen): AR(1), pink, thermal wander
// and probe-zero wander, at the instrument's sample times.
#include <cmath>
#include <random>

#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"

namespace rotacal {

namespace noise_gen {

namespace {
// AR(1) per stream with stationary start, unit... given marginal sigma.
void add_ar1(const std::vector<std::vector<Eigen::Index>>& streams, double rho, double sigma,
             std::mt19937_64& rng, Eigen::VectorXd& out) {
  std::normal_distribution<double> N(0.0, 1.0);
  const double innov = sigma * std::sqrt(std::max(0.0, 1.0 - rho * rho));
  for (const auto& s : streams) {
    double x = sigma * N(rng);
    for (std::size_t t = 0; t < s.size(); ++t) {
      if (t > 0) x = rho * x + innov * N(rng);
      out[s[t]] += x;
    }
  }
}
}  // namespace

Eigen::VectorXd ar1(const std::vector<std::string>& groups, const std::vector<double>& times,
                    double rho, double sigma_mm, std::uint64_t seed) {
  if (!(std::abs(rho) < 1.0)) throw InvalidArgument("noise_gen::ar1: rho must be in (-1, 1)");
  if (!(sigma_mm >= 0.0)) throw InvalidArgument("noise_gen::ar1: sigma_mm must be >= 0");
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(groups.size()));
  add_ar1(noise_streams(groups, times), rho, sigma_mm, rng, out);
  return out;
}

Eigen::VectorXd pink(const std::vector<std::string>& groups, const std::vector<double>& times,
                     double sigma_mm, std::uint64_t seed) {
  if (!(sigma_mm >= 0.0)) throw InvalidArgument("noise_gen::pink: sigma_mm must be >= 0");
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(groups.size()));
  const auto streams = noise_streams(groups, times);
  // Four equal-variance terms: the total marginal variance is sigma^2.
  for (double tau : {1.0, 10.0, 100.0, 1000.0})
    add_ar1(streams, std::exp(-1.0 / tau), sigma_mm / 2.0, rng, out);
  return out;
}

Eigen::VectorXd thermal_wander(const std::vector<double>& times, double amplitude_mm,
                               double period_s, std::uint64_t seed) {
  if (!(period_s > 0.0)) throw InvalidArgument("noise_gen::thermal_wander: period_s must be > 0");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double per[3], ph[3];
  for (int i = 0; i < 3; ++i) per[i] = period_s * (1.0 + 2.0 * U(rng)), ph[i] = 2.0 * M_PI * U(rng);
  Eigen::VectorXd out(static_cast<Eigen::Index>(times.size()));
  // Three sines of RMS a/sqrt(3) each: RMS a in all.
  const double a = amplitude_mm * std::sqrt(2.0 / 3.0);
  for (std::size_t i = 0; i < times.size(); ++i) {
    double v = 0.0;
    for (int k = 0; k < 3; ++k) v += a * std::sin(2.0 * M_PI * times[i] / per[k] + ph[k]);
    out[static_cast<Eigen::Index>(i)] = v;
  }
  return out;
}

Eigen::VectorXd probe_zero_wander(const std::vector<std::string>& groups,
                                  const std::vector<double>& times, double step_mm,
                                  std::uint64_t seed) {
  if (!(step_mm >= 0.0))
    throw InvalidArgument("noise_gen::probe_zero_wander: step_mm must be >= 0");
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, step_mm);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(groups.size()));
  for (const auto& s : noise_streams(groups, times)) {
    double z = 0.0;
    for (std::size_t t = 0; t < s.size(); ++t) {
      if (t > 0) z += N(rng);
      out[s[t]] = z;
    }
  }
  return out;
}

}  // namespace noise_gen

}  // namespace rotacal
