// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The size of a hidden effect at which detection is measured: the parameters that give k
/// sigma RMS of signal that the baseline model (location errors) cannot absorb, along the
/// effect's least-absorbable direction. Used by the diagnosis benchmarks.

#include <Eigen/SVD>
#include <cmath>
#include <vector>

#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/diagnose/ballbar_diagnosis.hpp"

namespace rotacal::synthetic {

/// Parameters of `e` giving k * noise_um RMS of unabsorbable signal on `cmd` simulated on
/// `truth`, or empty when that needs more than a plausible size of some parameter.
inline std::vector<double> unabsorbable_amplitude(const BallbarSession& cmd,
                                                  const BallbarMachineModel& truth, const Effect& e,
                                                  double k, double noise_um) {
  BallbarSession s = simulate_ballbar(cmd, truth, {0.0, 1, false});
  s.noise_um = noise_um;
  BallbarDiagnosisProblem P(s);
  const ModelFit at = P.fit(EffectModel{});
  Eigen::VectorXd m(e.num_params());
  for (int j = 0; j < m.size(); ++j)
    m[j] = plausible_magnitude(e.param_units()[static_cast<std::size_t>(j)]);
  const Eigen::MatrixXd Jc = P.candidate_jacobian(at, e) * m.asDiagonal();
  const Eigen::MatrixXd perp =
      Jc - at.jacobian * at.jacobian.completeOrthogonalDecomposition().solve(Jc);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(perp, Eigen::ComputeThinV);
  const double per_size = svd.singularValues()[0] / std::sqrt(static_cast<double>(perp.rows()));
  const double sizes = k * noise_um * 1e-3 / per_size;
  if (!(per_size > 0) || sizes * svd.matrixV().col(0).cwiseAbs().maxCoeff() > 1.0) return {};
  const Eigen::VectorXd p = m.cwiseProduct(svd.matrixV().col(0)) * sizes;
  return std::vector<double>(p.data(), p.data() + p.size());
}

}  // namespace rotacal::synthetic
