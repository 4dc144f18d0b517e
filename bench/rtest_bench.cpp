// R-test benchmark: joint-fit time for 2 nests x 84 poses, and held-out prediction RMS of the
// joint fit and of the paper's method (fit on C = 0, 30, ..; predict C = 15, 45, ..).
#include <time.h>

#include <chrono>
#include <cstdio>

#include "rotacal/rtest/error_map.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
// CPU time of this thread (s): on a shared machine the wall time also counts other processes.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
}  // namespace

int main() {
  MachineModel t = MachineModel::nominal(MachineType::BC_trt);  // ../shared/data/rtest_bc_oyama.truth.json + a 2-lobe face runout of C
  t.errors.v << 0.01459190348066346, 0.014212100597282357, 3.1102339878434216e-05,
      -2.385536385835234e-05, -0.016912021691263143, 0.017858631217842532,
      1.1379169104710182e-05, -4.973692463737003e-05;
  t.effects.effects = {Effect::parse("gravity_sag_B"), Effect::parse("coning_B"),
                       Effect::parse("axial_motion_C_h2")};
  t.effect_params = {0.006, 0.000145, 0.002, -0.001};
  const int runs = 10;
  double ms = 0.0, cpu_ms = 0.0, rms_joint = 0.0, rms_paper = 0.0, sigma = 0.0;
  for (int r = 0; r < runs; ++r) {
    RtestSimOptions o;
    o.seed = 100 + static_cast<unsigned>(r);
    const RtestSimulation fit = simulate_rtest(t, o);
    RtestSimOptions h = o;
    h.seed = 200 + static_cast<unsigned>(r);
    h.pattern.c_deg.clear();
    for (int j = 0; j < 12; ++j) h.pattern.c_deg.push_back(15.0 + 30.0 * j);
    const RtestSimulation held = simulate_rtest(t, h);
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    const RtestJointIdentification joint = identify_joint(fit.session);
    ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    cpu_ms += 1e3 * (cpu_seconds() - c0);
    sigma += joint.sigma_um;
    const RtestPaperIdentification paper = identify_paper(fit.session);
    rms_joint += prediction_rms_um(held.session, [&](const Eigen::Vector3d& q, double B, double C) {
      return joint.model.reading(q, B, C);
    });
    rms_paper += prediction_rms_um(held.session, [&](const Eigen::Vector3d& q, double B, double C) {
      return paper.predict_reading(q, B, C);
    });
  }
  std::printf("rtest joint fit, 2 x 84 poses: %.1f ms wall, %.1f ms CPU per fit (mean of %d; target <= 10 ms)\n",
              ms / runs, cpu_ms / runs, runs);
  std::printf("fit residual sigma: %.3f um (noise 0.300 um)\n", sigma / runs);
  std::printf("held-out prediction RMS: joint %.3f um, paper %.3f um\n", rms_joint / runs,
              rms_paper / runs);
  return 0;
}
