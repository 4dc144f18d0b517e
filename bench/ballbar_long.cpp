// SPDX-License-Identifier: BSD-3-Clause
// Long-session bench: a 10-minute single set-up ballbar test recorded at 1 kHz (600,000
// samples), built in memory from the program timeline on the Table 2 machine, identified by the
// joint fit. Prints the identification time and the process' peak memory; the figures
// (<= 3 s, <= 500 MB) are for `/usr/bin/time -v build/dev/bench/ballbar_long`.
//
// With --diagnose it runs the diagnosis of the same session instead and prints its time and
// the process' peak memory (issue 14: a 10-minute 1 kHz session in bounded memory).
//
// Usage: ballbar_long [--samples N] [--smoke] [--diagnose]
#include <sys/resource.h>
#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/ballbar/timeline.hpp"
#include "rotacal/diagnose/ballbar_diagnosis.hpp"

using namespace rotacal;

namespace {
// CPU time of this thread (s): on a shared machine the wall time also counts other processes.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}
}  // namespace

int main(int argc, char** argv) {
  long target = 600000;
  bool diagnose = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--samples") && i + 1 < argc)
      target = std::atol(argv[++i]);
    else if (!std::strcmp(argv[i], "--smoke"))
      target = 20000;
    else if (!std::strcmp(argv[i], "--diagnose"))
      diagnose = true;
    else {
      std::fprintf(stderr, "usage: ballbar_long [--samples N] [--smoke] [--diagnose]\n");
      return 2;
    }
  }
  const ProgramTimeline timeline(plan_ballbar_test(BallbarSetup{}));
  // The test rows of a recording (transitions left out) at a rate that gives `target` of them.
  long in_tests = 0;
  const int probe = 20000;
  for (int k = 0; k < probe; ++k)
    in_tests += timeline.at(timeline.duration() * k / probe).test != "transition";
  const long total =
      static_cast<long>(1.01 * static_cast<double>(target) * probe / std::max(in_tests, 1L)) + 1;
  BallbarSession commanded = timeline.header();
  commanded.samples.reserve(static_cast<std::size_t>(target) + 1000);
  for (long k = 0; k < total && static_cast<long>(commanded.samples.size()) < target; ++k) {
    BallbarSample s =
        timeline.at(timeline.duration() * static_cast<double>(k) / static_cast<double>(total));
    if (s.test != "transition") commanded.samples.push_back(std::move(s));
  }
  BallbarMachineModel truth;
  truth.machine = MachineType::AC_trt;
  truth.errors.v << 0.0726, -0.0202, 1.1284e-5, -1.13006e-4, 0.0283, 0.1041, 5.1954e-6, -4.1544e-5;
  truth.pivot = commanded.pivot + Eigen::Vector3d(0.012, -0.008, 0.015);
  BallbarSession session = simulate_ballbar(commanded, truth, {0.5, 1, true});
  const std::size_t n_samples = session.samples.size();
  commanded.samples.clear();
  commanded.samples.shrink_to_fit();
  const double rss_before = peak_rss_mb();

  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_seconds();
  if (diagnose) {
    const Diagnosis D = diagnose_ballbar(std::move(session));  // as a caller done with it would
    std::printf(
        "ballbar_long: %zu samples; diagnose_ballbar: %.2f s wall, %.2f s CPU, %zu "
        "finding(s)%s%s\n",
        n_samples, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
        cpu_seconds() - c0, D.findings.size(), D.findings.empty() ? "" : ", first ",
        D.findings.empty() ? "" : D.findings[0].effect.id().c_str());
    std::printf("  peak RSS: %.0f MB after building the session, %.0f MB after the diagnosis\n",
                rss_before, peak_rss_mb());
    return 0;
  }
  const BallbarIdentification id = identify_joint(session);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_seconds() - c0;
  double worst = 0.0;
  for (int j = 0; j < 8; ++j)
    worst = std::max(
        worst, std::abs(id.parameters[static_cast<std::size_t>(j)].value - truth.errors.v[j]) /
                   id.parameters[static_cast<std::size_t>(j)].std);
  std::printf("ballbar_long: %zu samples over %.0f s of program (%.0f Hz)\n",
              session.samples.size(), timeline.duration(),
              static_cast<double>(total) / timeline.duration());
  std::printf(
      "  identify_joint: %.2f s wall, %.2f s CPU (%d Jacobian and %d residual evaluations), "
      "converged %s\n",
      s, cpu, id.summary.jacobian_evaluations, id.summary.residual_evaluations,
      id.converged ? "yes" : "no");
  std::printf("  residual RMS %.3f um (noise 0.500); largest |estimate - truth| %.2f sigma\n",
              id.residual_rms_um, worst);
  std::printf("  peak RSS: %.0f MB after building the session, %.0f MB after the fit\n", rss_before,
              peak_rss_mb());
  return id.converged ? 0 : 1;
}
