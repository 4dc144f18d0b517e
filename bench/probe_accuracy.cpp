// SPDX-License-Identifier: BSD-3-Clause
// Touch-probe accuracy bench (issue 31, "Figures to reach"): AC-trt with Flynn et al.'s Table 2
// errors (as ../shared/data/probe_ac_table2.truth.json), 24 poses x 5 touches
// (default_probe_pattern), 0.5 um white noise per latched coordinate. Over N draws: the joint
// fit's RMSE per location error against its Cramer-Rao bound (sigma^2 (J^T J)^-1 at the truth,
// from the one probe problem), its fit time, and the cycles' method's RMSE (radius known and
// free) on the same draws. `--smoke`: 20 draws (CI); default 1000.
#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "rotacal/probe/identify.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/simulate.hpp"

using namespace rotacal;

namespace {
double cpu_seconds() {  // this thread's CPU time (s): other processes share the machine
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// 1 sigma of each location error at the truth: sigma^2 (J^T J)^-1 over the free parameters
// (location errors and sphere), J the probe problem's Jacobian.
Eigen::VectorXd cramer_rao(const ProbeSession& s, const MachineModel& t,
                           const Eigen::Vector3d& sphere, double sigma_mm) {
  const ProbeProblem problem(s);
  const ProbeParameterLayout& L = problem.layout();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(L.size());
  L.errors.of<8>(x) = t.errors.v;
  L.sphere.of<3>(x) = sphere;
  Eigen::VectorXd r(problem.num_residuals());
  Eigen::MatrixXd J(problem.num_residuals(), problem.num_parameters());
  problem.evaluate(x, r, &J);
  const Eigen::MatrixXd C = (J.transpose() * J).inverse() * sigma_mm * sigma_mm;
  return L.errors.of(C.diagonal()).cwiseSqrt();
}
}  // namespace

int main(int argc, char** argv) {
  const bool smoke = argc > 1 && std::strcmp(argv[1], "--smoke") == 0;
  const int draws = smoke ? 20 : 1000;
  MachineModel t = MachineModel::nominal(MachineType::AC_trt);
  t.errors.v << 0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06, -4.1544e-05;
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(t.machine);
  o.sphere_offset = Eigen::Vector3d(0.0012, 0.045, -0.0356);
  o.noise_um = 0.5;
  o.seed = 0;
  const ProbeSimulation clean = [&] {
    ProbeSimOptions q = o;
    q.noise_um = 0.0;
    return simulate_probe(t, q);
  }();
  const Eigen::VectorXd crb = cramer_rao(clean.session, t, clean.sphere_actual, o.noise_um * 1e-3);
  Eigen::VectorXd se_joint = Eigen::VectorXd::Zero(8), se_known = se_joint, se_free = se_joint;
  double cpu = 0.0;
  int unconverged = 0;
  for (int d = 0; d < draws; ++d) {
    o.seed = 1000 + static_cast<std::uint64_t>(d);
    const ProbeSession s = simulate_probe(t, o).session;
    const double c0 = cpu_seconds();
    const ProbeIdentification joint = identify_probe(s);
    cpu += cpu_seconds() - c0;
    unconverged += joint.converged ? 0 : 1;
    se_joint += (joint.model.errors.v - t.errors.v).cwiseAbs2();
    se_known += (identify_probe_cycles(s, {true}).model.errors.v - t.errors.v).cwiseAbs2();
    se_free += (identify_probe_cycles(s, {false}).model.errors.v - t.errors.v).cwiseAbs2();
  }
  const auto rmse = [&](const Eigen::VectorXd& se) {
    return Eigen::VectorXd((se / draws).cwiseSqrt());
  };
  const Eigen::VectorXd rj = rmse(se_joint), rk = rmse(se_known), rf = rmse(se_free);
  std::printf(
      "probe_accuracy: AC-trt, Flynn Table 2 errors, 24 poses x 5 touches, 0.5 um white, %d "
      "draws%s\n",
      draws, smoke ? " (--smoke)" : "");
  std::printf("joint fit: %.3f ms CPU per fit (mean; target <= 1 ms), %d not converged\n",
              1e3 * cpu / draws, unconverged);
  std::printf("%-7s %5s %10s %10s %9s %12s %12s %10s %10s\n", "error", "unit", "CRB", "joint",
              "joint/CRB", "cycles(R)", "cycles(free)", "joint/cyc", "cyc(R)/CRB");
  const auto& names = location_error_names(t.machine);
  for (int k = 0; k < 8; ++k) {
    const bool angle = location_error_is_angle(k);
    const double u = angle ? 1e6 : 1e3;  // urad, um
    std::printf("%-7s %5s %10.4f %10.4f %9.3f %12.4f %12.4f %10.4f %10.3f\n",
                names[static_cast<std::size_t>(k)].c_str(), angle ? "urad" : "um", u * crb[k],
                u * rj[k], rj[k] / crb[k], u * rk[k], u * rf[k], rj[k] / rk[k], rk[k] / crb[k]);
  }
  return 0;
}
