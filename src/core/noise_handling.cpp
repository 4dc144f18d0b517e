// Bootstrap bias factor of a noise model estimated from fit residuals (core/noise_handling.hpp).
#include "rotacal/core/noise_handling.hpp"

#include <algorithm>
#include <random>

#include <Eigen/QR>

#include "rotacal/core/error.hpp"

namespace rotacal {

NoiseHandling noise_handling_from_string(const std::string& noise) {
  if (noise == "auto") return NoiseHandling::automatic;
  if (noise == "white") return NoiseHandling::white;
  throw InvalidArgument("noise: expected 'auto' or 'white', got '" + noise + "'");
}

Eigen::VectorXd draw_noise(const NoiseModel& model, std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.n));
  for (const NoiseStream& s : model.streams) {
    const std::size_t p = s.ar.size();
    const double se = s.innovation_sigma_um * 1e-3;
    // Stationary start: run the recursion for many correlation times before the first row.
    const std::size_t burn = p == 0 ? 0 : 200 + static_cast<std::size_t>(20.0 * s.correlation_samples);
    std::vector<double> hist(p, 0.0);  // hist[k]: x_{t-1-k}
    const std::size_t total = burn + s.rows.size();
    for (std::size_t t = 0; t < total; ++t) {
      double x = se * N(rng);
      for (std::size_t k = 0; k < p; ++k) x += s.ar[k] * hist[k];
      if (p > 0) {
        std::rotate(hist.rbegin(), hist.rbegin() + 1, hist.rend());
        hist[0] = x;
      }
      if (t >= burn) e[s.rows[t - burn]] = x;
    }
    // The random walk from the stream's first reading (its start is the stream's level).
    if (s.random_walk_step_um > 0.0) {
      const double q = s.random_walk_step_um * 1e-3;
      double z = 0.0;
      for (std::size_t t = 0; t < s.rows.size(); ++t) {
        if (t > 0) z += q * N(rng);
        e[s.rows[t]] += z;
      }
    }
  }
  return e;
}

double long_run_variance(const NoiseModel& model) {
  double v = 0.0;
  for (const NoiseStream& s : model.streams) {
    double sum_phi = 0.0;
    for (double p : s.ar) sum_phi += p;
    const double se = s.innovation_sigma_um * 1e-3;
    v += static_cast<double>(s.rows.size()) * se * se / std::max(1e-12, (1.0 - sum_phi) * (1.0 - sum_phi));
  }
  return v;
}

double noise_model_bias_factor(const NoiseModel& model, const std::vector<std::string>& groups,
                               const std::vector<double>& times, const Eigen::MatrixXd& jacobian_free,
                               const NoiseModelOptions& options, int draws, std::uint64_t seed) {
  const Eigen::Index n = static_cast<Eigen::Index>(groups.size());
  if (times.size() != groups.size() || jacobian_free.rows() != n || static_cast<Eigen::Index>(model.n) != n)
    throw InvalidArgument("noise_model_bias_factor: groups, times, jacobian_free rows and model.n must agree (" +
                          std::to_string(groups.size()) + ", " + std::to_string(times.size()) + ", " +
                          std::to_string(jacobian_free.rows()) + ", " + std::to_string(model.n) + ")");
  if (draws < 1) throw InvalidArgument("noise_model_bias_factor: draws must be >= 1");
  const double target = long_run_variance(model);
  if (model.white() || !(target > 0.0)) return 1.0;
  // Column-pivoted QR: projection onto the fitted directions, robust to scaling of columns.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jacobian_free);
  const Eigen::Index rank = qr.rank();
  const Eigen::MatrixXd Q = Eigen::MatrixXd(qr.householderQ()).leftCols(rank);
  std::mt19937_64 rng(seed);
  Eigen::VectorXd e(n);
  double sum = 0.0;
  for (int d = 0; d < draws; ++d) {
    e = draw_noise(model, rng);
    const Eigen::VectorXd r = e - Q * (Q.transpose() * e);
    sum += long_run_variance(estimate_noise_model(groups, times, r, options));
  }
  const double mean = sum / draws;
  return mean > 0.0 ? std::max(1.0, target / mean) : 1.0;
}

}  // namespace rotacal
