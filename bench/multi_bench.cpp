// SPDX-License-Identifier: BSD-3-Clause
// Joint ballbar + touch-probe identification of one AC-trt machine (issue 31, item 5, "Figures
// to reach"): over N draws of both sessions (the ballbar's default single set-up plan, 0.5 um
// white noise; the probe's default 24 poses x 5 touches, 0.5 um AR(1) noise with rho 0.5 from
// touch to touch), per location error: the joint fit's Monte Carlo sigma / its mean reported
// sigma (target 0.9-1.1), and the sigma jointly and from each instrument alone (the table of
// BENCHMARKS.md), and each session alone's Monte Carlo / reported sigma. `--smoke`: 10 draws;
// `--draws N`; default 200.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/multi/identify.hpp"
#include "rotacal/probe/simulate.hpp"

using namespace rotacal;

namespace {
// Running mean and sample standard deviation.
struct Moments {
  double n = 0, sum = 0, sum2 = 0;
  void add(double v) {
    n += 1;
    sum += v;
    sum2 += v * v;
  }
  double mean() const { return sum / n; }
  double sd() const { return std::sqrt(std::max(0.0, (sum2 - sum * sum / n) / (n - 1))); }
};
}  // namespace

int main(int argc, char** argv) {
  int draws = 200;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--smoke") == 0)
      draws = 10;
    else if (std::strcmp(argv[k], "--draws") == 0 && k + 1 < argc)
      draws = std::atoi(argv[++k]);
  }
  MachineModel t = MachineModel::nominal(MachineType::AC_trt);
  t.errors.v << 0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06, -4.1544e-05;
  BallbarSetup setup;
  setup.machine = t.machine;
  const BallbarSession cmd = commanded_session(plan_ballbar_test(setup));
  BallbarMachineModel b;
  static_cast<MachineModel&>(b) = t;
  b.pivot = cmd.pivot + Eigen::Vector3d(0.012, -0.008, 0.015);
  ProbeSimOptions po;
  po.pattern = default_probe_pattern(t.machine);
  po.sphere_offset = Eigen::Vector3d(0.0012, 0.045, -0.0356);
  po.noise_um = 0.5;
  po.ar1_rho = 0.5;

  const auto& names = location_error_names(t.machine);
  // [error]: joint values, joint reported sigma, alone reported sigma (ballbar, probe), alone
  // values.
  std::vector<Moments> value(8), reported(8), alone_bb(8), alone_pr(8), value_bb(8), value_pr(8);
  std::vector<int> unobservable(8, 0);
  int disagreeing = 0;
  for (int d = 0; d < draws; ++d) {
    po.seed = 1000 + static_cast<std::uint64_t>(d);
    const MultiIdentification id = identify_multi(
        {MultiSessionInput::of(
             "ballbar",
             simulate_ballbar(cmd, b, {0.5, 2000 + static_cast<std::uint64_t>(d), true})),
         MultiSessionInput::of("probe", simulate_probe(t, po).session)});
    if (!id.disagreements.empty()) ++disagreeing;
    for (int j = 0; j < 8; ++j) {
      const ParameterEstimate p = id.location_errors()[static_cast<std::size_t>(j)];
      if (!p.observable) {
        ++unobservable[static_cast<std::size_t>(j)];
        continue;
      }
      value[j].add(p.value - t.errors.v[j]);
      reported[j].add(p.std * p.std);
      const ParameterEstimate &a = id.sessions[0].alone[static_cast<std::size_t>(j)],
                              &c = id.sessions[1].alone[static_cast<std::size_t>(j)];
      if (a.observable) {
        alone_bb[j].add(a.std * a.std);
        value_bb[j].add(a.value);
      }
      if (c.observable) {
        alone_pr[j].add(c.std * c.std);
        value_pr[j].add(c.value);
      }
    }
  }
  std::printf(
      "joint ballbar + probe, AC-trt, %d draws (sigma in um / urad; reported = RMS of the reported "
      "1 sigma)\n",
      draws);
  std::printf("%-6s %10s %10s %7s | %10s %10s %10s | %9s %9s\n", "error", "MC sigma", "reported",
              "ratio", "joint", "ballbar", "probe", "bb ratio", "pr ratio");
  for (int j = 0; j < 8; ++j) {
    const double f = location_error_is_angle(j) ? 1e6 : 1e3;
    if (unobservable[static_cast<std::size_t>(j)]) {
      std::printf("%-6s unobservable in %d draws\n", names[static_cast<std::size_t>(j)].c_str(),
                  unobservable[static_cast<std::size_t>(j)]);
      continue;
    }
    const double rep = std::sqrt(reported[j].mean());
    auto alone = [&](const Moments& m) { return m.n > 0 ? std::sqrt(m.mean()) * f : NAN; };
    // The sessions alone: Monte Carlo sigma / reported sigma (what the disagreement test rests on).
    auto ratio = [&](const Moments& v, const Moments& m) {
      return v.n > 1 ? v.sd() / std::sqrt(m.mean()) : NAN;
    };
    std::printf("%-6s %10.4f %10.4f %7.3f | %10.4f %10.4f %10.4f | %9.3f %9.3f\n",
                names[static_cast<std::size_t>(j)].c_str(), value[j].sd() * f, rep * f,
                value[j].sd() / rep, rep * f, alone(alone_bb[j]), alone(alone_pr[j]),
                ratio(value_bb[j], alone_bb[j]), ratio(value_pr[j], alone_pr[j]));
  }
  std::printf(
      "draws with a reported disagreement (the sessions alone, at identify's "
      "multiplicity-corrected threshold): %d of %d\n",
      disagreeing, draws);
  return 0;
}
