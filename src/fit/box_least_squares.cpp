// SPDX-License-Identifier: BSD-3-Clause
// Bounded linear least squares by cyclic coordinate descent (fit/box_least_squares.hpp).
#include "rotacal/fit/box_least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "rotacal/core/error.hpp"

namespace rotacal {

Eigen::VectorXd box_least_squares(const Eigen::MatrixXd& R, const Eigen::VectorXd& d,
                                  const Eigen::VectorXd& w, const Eigen::VectorXd& bounds,
                                  const BoxLeastSquaresOptions& options) {
  const Eigen::Index n = R.rows(), k = R.cols();
  if (d.size() != n || w.size() != n || bounds.size() != k)
    throw InvalidArgument("box_least_squares: R is " + std::to_string(n) + " x " +
                          std::to_string(k) + ", d has " + std::to_string(d.size()) +
                          " values, w " + std::to_string(w.size()) + ", bounds " +
                          std::to_string(bounds.size()));
  if (!R.allFinite() || !d.allFinite() || !w.allFinite() || !bounds.allFinite())
    throw InvalidArgument("box_least_squares: R, d, w and bounds must be finite");
  if ((w.array() < 0.0).any()) throw InvalidArgument("box_least_squares: weights must be >= 0");
  if ((bounds.array() < 0.0).any()) throw InvalidArgument("box_least_squares: bounds must be >= 0");
  if (options.max_sweeps < 1 || !(options.tolerance > 0.0))
    throw InvalidArgument("box_least_squares: options.max_sweeps must be >= 1 and tolerance > 0");

  Eigen::VectorXd s = Eigen::VectorXd::Zero(k), old(k);
  // e = d - R s, kept up to date as one coordinate changes at a time.
  Eigen::VectorXd e = d;
  const Eigen::VectorXd den =
      (R.array().square().colwise() * w.array()).colwise().sum().transpose();
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    old = s;
    for (Eigen::Index j = 0; j < k; ++j) {
      // The minimum along s_j with the others held: sum w r (e + r s_j) / sum w r^2.
      const double sj =
          den[j] > 0.0
              ? std::clamp(
                    (w.array() * R.col(j).array() * (e + R.col(j) * s[j]).array()).sum() / den[j],
                    -bounds[j], bounds[j])
              : 0.0;
      e -= R.col(j) * (sj - s[j]);
      s[j] = sj;
    }
    double moved = 0.0;
    for (Eigen::Index j = 0; j < k; ++j)
      moved = std::max(moved, std::abs(s[j] - old[j]) / std::max(bounds[j], 1e-300));
    if (moved < options.tolerance) break;
  }
  return s;
}

}  // namespace rotacal
