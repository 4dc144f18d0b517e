// SPDX-License-Identifier: BSD-3-Clause
// How sure a finding is of its name (src/diagnose/rivals.hpp): a candidate whose evidence the
// chosen one explains away is its rival even where their fitted signatures correlate little,
// and an effect of its own beside the chosen one is not. Exact readings built from orthonormal
// directions, so every chi-square change below is known in closed form.
#include <Eigen/QR>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "../../src/diagnose/rivals.hpp"

using namespace rotacal;
using namespace rotacal::diagnosis_detail;

namespace {

Effect effect(EffectKind kind, char axis) {
  Effect e;
  e.kind = kind;
  e.axis = axis;
  return e;
}

// A one-column candidate scored as the search scores it: its least-squares fit to in.r_w.
Score one_column(const Effect& e, const Eigen::VectorXd& a, const ScoringInputs& in) {
  Score s;
  s.effect = e;
  s.observable = true;
  s.k = 1;
  s.A = a;
  const double d = a.dot(in.r_w) / a.squaredNorm(), rr = in.r_w.squaredNorm();
  s.signature = a * d;
  s.rss1 = rr - d * a.dot(in.r_w);
  const double n = static_cast<double>(in.r_w.size());
  s.delta_bic = n * std::log(s.rss1 / rr) + std::log(n);
  s.f_pvalue = 1e-6;
  return s;
}

}  // namespace

TEST_CASE("A rival explained away by the chosen cause is weighed, an effect of its own is not",
          "[rivals]") {
  const Eigen::Index n = 400;
  std::mt19937 rng(11);
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::MatrixXd G(n, 5);
  for (Eigen::Index j = 0; j < G.cols(); ++j)
    for (Eigen::Index i = 0; i < n; ++i) G(i, j) = N(rng);
  const Eigen::MatrixXd Q =
      Eigen::HouseholderQR<Eigen::MatrixXd>(G).householderQ() * Eigen::MatrixXd::Identity(n, 5);
  const Eigen::VectorXd u = Q.col(0), w = Q.col(1), z = Q.col(2), v = Q.col(3), q = Q.col(4);
  // Readings: 6 along the chosen cause, 3.5 along what only the rival adds, 5 along an effect of
  // its own, and noise of chi-square 360 elsewhere.
  ScoringInputs in;
  in.r_w = 6.0 * u + 3.5 * w + 5.0 * z + std::sqrt(360.0) * v;
  const Score chosen = one_column(effect(EffectKind::radial_motion, 'C'), u, in);
  // Its signature correlates with the chosen one's by 0.45 (under rival_correlation 0.5); alone it
  // explains 33.9 of chi-square against the chosen one's 36, beside it 12.25: short of -10.
  const Score rival = one_column(effect(EffectKind::tilt_motion, 'C'),
                                 0.45 * u + std::sqrt(1.0 - 0.45 * 0.45) * w, in);
  const Score own = one_column(effect(EffectKind::thermal_drift, 'X'), z, in);
  REQUIRE(chosen.delta_bic < -10.0);
  REQUIRE(rival.delta_bic < -10.0);
  REQUIRE(own.delta_bic < -10.0);
  REQUIRE(std::abs(correlation(rival.signature, chosen.signature)) == Approx(0.45).epsilon(1e-9));

  const std::vector<const Score*> field{&chosen, &rival, &own};
  const std::vector<double> bic{chosen.delta_bic, rival.delta_bic, own.delta_bic};
  const std::vector<bool> away = explained_away(in, chosen, field, -10.0, 0.5);
  CHECK(away == std::vector<bool>{false, true, false});
  // The rival beside the chosen cause, worked out: 400 ln(1 - 12.25 / 397.25) + ln 400.
  const double beside = 400.0 * std::log(1.0 - 12.25 / 397.25) + std::log(400.0);
  CHECK(beside > -10.0);
  CHECK(beside < -5.0);

  // Without the rule the chosen cause is named alone; with it, it shares the weight.
  const RivalJudgement alone =
      weigh_rivals(chosen, field, bic, static_cast<double>(n), 1.0, 0.5, 0.9);
  CHECK(alone.group.size() == 1);
  CHECK(alone.weight == Approx(1.0));
  const RivalJudgement judged =
      weigh_rivals(chosen, field, bic, static_cast<double>(n), 1.0, 0.5, 0.9, away);
  REQUIRE(judged.group.size() == 2);
  CHECK(judged.group[1] == &rival);
  CHECK(judged.weight < 0.9);
  CHECK(judged.weight > 0.5);

  // A correlated rival is not judged again (it is one anyway), nor a candidate short of -10 alone.
  const Score close =
      one_column(effect(EffectKind::axial_motion, 'C'), 0.9 * u + std::sqrt(1.0 - 0.81) * w, in);
  const Score weak =
      one_column(effect(EffectKind::linear_scale, 'Y'), 0.2 * z + std::sqrt(1.0 - 0.04) * q, in);
  REQUIRE(weak.delta_bic > -10.0);
  CHECK(explained_away(in, chosen, {&close, &weak}, -10.0, 0.5) == std::vector<bool>{false, false});
}
