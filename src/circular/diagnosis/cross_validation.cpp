// SPDX-License-Identifier: BSD-3-Clause
// Cross-validation of the circular-test diagnosis: blocked folds within each run, and the CV RMS
// of a model refitted without each fold (the engine's blocked_cv_rms_um, refitted with each
// run's own baseline).
#include "../../diagnose/scoring.hpp"
#include "diagnosis_detail.hpp"

namespace rotacal::circular_detail {

// Each run's rows (contiguous, in time order: gather appends runs in order) cut into K blocks.
std::vector<int> run_folds(const Rows& R, int K) {
  std::vector<int> f(R.n);
  for (std::size_t k = 0; k < R.runs; ++k) {
    const auto count = static_cast<std::size_t>(R.run_count[k]);
    for (std::size_t i = 0; i < count; ++i)
      f[static_cast<std::size_t>(R.run_first[k]) + i] =
          diagnosis_detail::contiguous_block(i, count, K);
  }
  return f;
}

// Blocked cross-validated RMS (um) of predicting y from the columns M = [B | E] (unwhitened):
// each fold's refit by block_solve on the training rows, regrouped run by run.
double cv_rms_um(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y,
                 const std::vector<int>& fold, int K) {
  return diagnosis_detail::blocked_cv_rms_um(
      M, y, fold, K, [&](const std::vector<Eigen::Index>& train) {
        std::vector<Eigen::Index> first(R.runs, 0), count(R.runs, 0);
        for (std::size_t j = 0; j < train.size(); ++j) {
          const auto run = static_cast<std::size_t>(R.run[static_cast<std::size_t>(train[j])]);
          if (count[run] == 0) first[run] = static_cast<Eigen::Index>(j);
          ++count[run];
        }
        return block_solve(first, count, M(train, Eigen::all), y(train));
      });
}

}  // namespace rotacal::circular_detail
