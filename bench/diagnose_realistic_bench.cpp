// Diagnosis of single set-up ballbar sessions in coloured noise: false findings on null
// sessions with AR(1) noise (rho 0.5, 0.9, 0.95) and 1/f-like noise, white null as control,
// hidden catalogue effects in AR(1) noise named first, and the time the noise model costs
// (median, same sessions diagnosed with the noise treated as white).
// Targets (issue 11): false findings <= 5 %; white null 0; named first >= 90 % at three times
// the white-noise half-detection amplitude; time with the noise model <= 1.3x white.
//
// Usage: diagnose_realistic_bench [--null N] [--trials N] [--rho R (0 white, -1 1/f-like)] [--smoke]
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/ballbar/test_plan.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/diagnose/ballbar_diagnosis.hpp"
#include "../tests/support/detection_amplitude.hpp"
#include "../tests/support/synthetic_sessions.hpp"

using namespace rotacal;

namespace {
constexpr double kNoiseUm = 0.5;

bool named_first(const Diagnosis& D, const Effect& e) {
  if (D.findings.empty()) return false;
  if (D.findings[0].effect == e) return true;
  for (const Ambiguity& g : D.ambiguous)
    if (g.effects[0] == D.findings[0].effect.id() &&
        std::find(g.effects.begin(), g.effects.end(), e.id()) != g.effects.end())
      return true;
  return false;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main(int argc, char** argv) {
  int n_null = 200, trials = 5;
  std::vector<double> rhos = {0.0, 0.5, 0.9, 0.95, -1.0};  // 0: white, -1: 1/f-like
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--null") && i + 1 < argc) n_null = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--trials") && i + 1 < argc) trials = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--smoke")) n_null = 3, trials = 1;
    else if (!std::strcmp(argv[i], "--rho") && i + 1 < argc) rhos = {std::atof(argv[++i])};
    else {
      std::fprintf(stderr, "usage: diagnose_realistic_bench [--null N] [--trials N] [--rho R] [--smoke]\n");
      return 2;
    }
  }
  const BallbarSession cmd = commanded_session(plan_ballbar_test(BallbarSetup{}));
  std::printf("diagnose_realistic_bench: AC-trt single set-up, %zu samples, marginal noise %.1f um\n",
              cmd.samples.size(), kNoiseUm);
  std::printf("%-22s %14s %14s %12s %12s %9s\n", "null sessions", "findings(AR)", "findings(wht)",
              "unexplained", "median ms", "ms white");
  DiagnosisOptions white;
  white.model_noise = false;
  for (double rho : rhos) {
    std::mt19937 rng(2024);
    int fm = 0, fw = 0, un = 0;
    std::vector<double> ms, ms_white;
    for (int k = 0; k < n_null; ++k) {
      const BallbarSession s = synthetic::noisy_ballbar(cmd, synthetic::random_ballbar_machine(cmd, rng), rho, kNoiseUm, static_cast<std::uint64_t>(k + 1));
      auto t0 = std::chrono::steady_clock::now();
      const Diagnosis D = diagnose_ballbar(s);
      ms.push_back(ms_since(t0));
      t0 = std::chrono::steady_clock::now();
      const Diagnosis W = diagnose_ballbar(s, white);
      ms_white.push_back(ms_since(t0));
      fm += !D.findings.empty();
      fw += !W.findings.empty();
      un += D.unexplained.present;
    }
    std::sort(ms.begin(), ms.end());
    std::sort(ms_white.begin(), ms_white.end());
    const std::string name = rho == 0.0 ? "white" : rho < 0 ? "1/f-like" : "AR(1) rho " + std::to_string(rho).substr(0, 4);
    std::printf("%-22s %8d/%-5d %8d/%-5d %6d/%-5d %12.0f %9.0f\n", name.c_str(), fm, n_null, fw, n_null, un,
                n_null, ms[ms.size() / 2], ms_white[ms_white.size() / 2]);
  }

  // Hidden effects in AR(1) noise at 0.45 sigma RMS of unabsorbable signal: three times the
  // ~0.15 sigma at which diagnose_bench's white-noise detection passes 50 %.
  for (double rho : {0.5, 0.9}) {
    std::printf("\nhidden effects at 0.45 sigma RMS in AR(1) rho %.2f, %d trial(s) each: named first\n", rho, trials);
    int hits = 0, done = 0;
    std::string missed;
    std::mt19937 rng(7);
    for (const Effect& e : effect_catalogue(MachineType::AC_trt, 3)) {
      int h = 0, d = 0;
      for (int t = 0; t < trials; ++t) {
        BallbarMachineModel truth = synthetic::random_ballbar_machine(cmd, rng);
        const std::vector<double> p = synthetic::unabsorbable_amplitude(cmd, truth, e, 0.45, kNoiseUm);
        if (p.empty()) break;
        truth.effects.effects = {e};
        truth.effect_params = p;
        const Diagnosis D = diagnose_ballbar(synthetic::noisy_ballbar(cmd, truth, rho, kNoiseUm, static_cast<std::uint64_t>(900 + t)));
        ++d;
        h += named_first(D, e);
      }
      if (d == 0) continue;
      hits += h, done += d;
      if (h < d) missed += " " + e.id() + " " + std::to_string(h) + "/" + std::to_string(d);
    }
    std::printf("  %d of %d sessions (%.0f %%); missed:%s\n", hits, done, done ? 100.0 * hits / done : 0.0,
                missed.empty() ? " none" : missed.c_str());
  }
  return 0;
}
