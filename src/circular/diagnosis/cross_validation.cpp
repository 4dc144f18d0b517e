// Cross-validation of the circular-test diagnosis: blocked folds within each run, and the CV RMS
// of a model refitted without each fold.
#include "diagnosis_detail.hpp"

#include <cmath>
#include <map>

namespace rotacal::circular_detail {

std::vector<int> run_folds(const Rows& R, int K) {
  std::vector<int> f(R.n);
  std::map<int, std::pair<std::size_t, std::size_t>> span;  // run -> first row, count
  for (std::size_t i = 0; i < R.n; ++i) {
    auto it = span.find(R.run[i]);
    if (it == span.end())
      span[R.run[i]] = {i, 1};
    else
      ++it->second.second;
  }
  for (std::size_t i = 0; i < R.n; ++i) {
    const auto& sp = span[R.run[i]];
    f[i] = static_cast<int>((i - sp.first) * static_cast<std::size_t>(K) / sp.second);
  }
  return f;
}

// Blocked cross-validated RMS (um) of predicting y from the columns M = [B | E] (unwhitened,
// as diagnosis_detail::cv_rms_um, which it equals): refit on all blocks but one of every run
// by block_solve, predict the left-out rows.
double cv_rms_um(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y,
                 const std::vector<int>& fold, int K) {
  double ss = 0.0;
  std::size_t n = 0;
  for (int k = 0; k < K; ++k) {
    std::vector<Eigen::Index> tr, te;
    std::vector<Eigen::Index> first(R.runs, 0), count(R.runs, 0);
    for (std::size_t i = 0; i < fold.size(); ++i) {
      if (fold[i] == k) {
        te.push_back(static_cast<Eigen::Index>(i));
      } else {
        const std::size_t run = static_cast<std::size_t>(R.run[i]);
        if (count[run] == 0) first[run] = static_cast<Eigen::Index>(tr.size());
        ++count[run];
        tr.push_back(static_cast<Eigen::Index>(i));
      }
    }
    if (te.empty() || tr.empty()) continue;
    const Eigen::VectorXd d =
        block_solve(first, count, M(tr, Eigen::all), y(tr));
    ss += (y(te) - M(te, Eigen::all) * d).squaredNorm();
    n += te.size();
  }
  return n ? std::sqrt(ss / static_cast<double>(n)) * 1e3 : 0.0;
}

}  // namespace rotacal::circular_detail
