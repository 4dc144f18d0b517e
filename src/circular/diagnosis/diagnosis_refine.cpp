// SPDX-License-Identifier: BSD-3-Clause
// The nonlinear parameters of the circular-test diagnosis' findings (a spike's time constant,
// a reversal delay): profiled, every linear parameter refitted at each trial; golden section
// for ln tau, a scan of the delay's staircase profile.
#include <algorithm>
#include <cmath>
#include <memory>

#include "../../diagnose/scoring.hpp"
#include "diagnosis_detail.hpp"

namespace rotacal::circular_detail {

namespace {

double golden(const std::function<double(double)>& f, double a, double b) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 30 && b - a > 1e-6 * (1.0 + std::abs(a)); ++it) {
    if (f1 <= f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = f(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = f(x2);
    }
  }
  return 0.5 * (a + b);
}

}  // namespace

// The whitened RSS of the whole model refitted with one nonlinear parameter (*field) at value.
double CircularSearch::rss_with(double* field, double value) {
  const double keep = *field;
  *field = value;
  const double v = gls(R, model_columns(R, B, chosen, o_.screw_pitch), R.y, W).rss_w;
  *field = keep;
  return v;
}

// The profile of entry k's nonlinear parameters with the rest of the model fixed in
// structure: whitened residual of y on the other columns, then the entry's columns projected
// on what is left (Frisch-Waugh), O(n p) per trial instead of a full refit.
std::function<double(double, double)> CircularSearch::profile_of(std::size_t k) {
  std::vector<Chosen> others = chosen;
  others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
  const ModelBasis Q(R, W(model_columns(R, B, others, o_.screw_pitch)));
  const Eigen::VectorXd r0 = Q.project_out(W(Eigen::MatrixXd(R.y))).col(0);
  const CircularEffect e = chosen[k].effect;
  // A trial whose columns equal the previous trial's (a delay step that crosses no reading)
  // has its value: the same computation on the same numbers.
  auto last = std::make_shared<std::pair<Eigen::MatrixXd, double>>();
  return [this, Q, r0, e, last](double tau, double delay) {
    Eigen::MatrixXd J = effect_columns(R, e, o_.screw_pitch, tau, delay);
    if (last->first.size() == J.size() && last->first == J) return last->second;
    const Eigen::MatrixXd A = Q.project_out(W(J));
    const Eigen::VectorXd d = diagnosis_detail::solve_ls(A, r0);
    *last = {std::move(J), (r0 - A * d).squaredNorm()};
    return last->second;
  };
}

// A reversal delay moves a step in time: the model changes only when a step crosses a
// reading, so the profile is a staircase. Scan it (0..20 ms by 0.5 ms, then +-0.5 ms by
// 0.05 ms) and take the middle of the lowest stair; its width is the resolution.
void CircularSearch::scan_delay(std::size_t k, const std::function<double(double, double)>& f) {
  Chosen& c = chosen[k];
  double best = c.delay, fbest = f(c.tau, c.delay);
  for (double x = 0.0; x <= 0.020 + 1e-12; x += 0.0005) {
    const double v = f(c.tau, x);
    if (v < fbest) fbest = v, best = x;
  }
  std::vector<double> xs, fs;
  for (double x = std::max(0.0, best - 0.002); x <= best + 0.002 + 1e-12; x += 0.00005) {
    xs.push_back(x);
    fs.push_back(f(c.tau, x));
  }
  const double fmin = *std::min_element(fs.begin(), fs.end());
  std::size_t i0 = 0;
  while (fs[i0] > fmin * (1.0 + 1e-12)) ++i0;
  std::size_t i1 = i0;
  while (i1 + 1 < fs.size() && fs[i1 + 1] <= fmin * (1.0 + 1e-12)) ++i1;
  c.delay = 0.5 * (xs[i0] + xs[i1]);
  // 1 sigma: half the range where the profile stays within delta chi-square 1 of its minimum
  // (whitened residuals have unit variance: s2 = fmin / dof), at least the stair's own
  // uniform spread.
  const double s2p = fmin / static_cast<double>(R.n);
  std::size_t j0 = i0, j1 = i1;
  while (j0 > 0 && fs[j0 - 1] <= fmin + s2p) --j0;
  while (j1 + 1 < fs.size() && fs[j1 + 1] <= fmin + s2p) ++j1;
  c.delay_range = {xs[j0], xs[j1]};
  c.delay_sd =
      std::max(std::max(xs[i1] - xs[i0], 0.00005) / std::sqrt(12.0), 0.5 * (xs[j1] - xs[j0]));
}

// Nonlinear parameters (a spike's ln tau, a reversal delay): golden section about the grid
// value, every linear parameter refitted at each trial (a profile), two sweeps.
void CircularSearch::refine() {
  for (int sweep = 0; sweep < 2; ++sweep)
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      Chosen& c = chosen[k];
      if (!nonlinear_params(c.effect)) continue;
      const std::function<double(double, double)> f = profile_of(k);
      if (c.effect.kind == CircularEffectKind::reversal_spike)
        c.tau = std::exp(golden([&](double x) { return f(std::exp(x), c.delay); },
                                std::log(c.tau) - 0.7, std::log(c.tau) + 0.7));
      scan_delay(k, f);
    }
}

}  // namespace rotacal::circular_detail
