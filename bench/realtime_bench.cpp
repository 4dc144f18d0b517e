// SPDX-License-Identifier: BSD-3-Clause
// Time per call of the real-time evaluation (include/rotacal/realtime/evaluate.hpp) with every
// catalogue term of the machine (harmonics 1..2, location errors, thermal gains): forward,
// inverse and forward_world (the forward a controller's world coordinates need: forward and the
// nominal angles of the tool direction; linuxcnc/rotacal_kins.cpp calls it), median and 99.9th
// percentile of each call timed alone (steady_clock around it, its own cost included), and the
// inverse's worst round trip as the accuracy figure. On a busy computer the maximum measures
// preemption, not the code, so it is not reported.
//   realtime_bench [--smoke] [--calls N]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "rotacal/io/realtime_export.hpp"
#include "rotacal/realtime/evaluate.hpp"

using namespace rotacal;

namespace {

realtime::Model every_term(MachineType m, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  LocationErrors<double> e;
  for (int i = 0; i < 8; ++i) e.v[i] = (location_error_is_angle(i) ? 1e-4 : 0.05) * n(rng);
  EffectModel fx;
  fx.effects = effect_catalogue(m, 2);
  fx.linear_reference = Eigen::Vector3d(20, -10, 50);
  std::vector<double> p;
  for (const Effect& f : fx.effects)
    for (const std::string& u : f.param_units())
      p.push_back(u == "mm" ? 0.01 * n(rng) : u == "1" ? 0.3 * n(rng) : 2e-5 * n(rng));
  realtime::Model rt = realtime_model(m, e, fx, p, "bench");
  rt.thermal_gain(0, 0) = 0.003;
  rt.thermal_gain(4, 1) = -0.002;
  return rt;
}

struct Times {
  double median_us, p999_us;
};
Times summarise(std::vector<double>& ns) {
  std::sort(ns.begin(), ns.end());
  return {ns[ns.size() / 2] * 1e-3, ns[static_cast<std::size_t>(0.999 * (ns.size() - 1))] * 1e-3};
}

}  // namespace

int main(int argc, char** argv) {
  long calls = 1000000;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke")) calls = 10000;
    if (!std::strcmp(argv[i], "--calls") && i + 1 < argc) calls = std::atol(argv[++i]);
  }
  std::printf("%-16s %8s %22s %22s %14s %22s\n", "machine", "effects", "forward us (50%, 99.9%)",
              "inverse us (50%, 99.9%)", "round trip um", "fwd world us (50%, 99.9%)");
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table"}) {
    std::mt19937 rng(55);
    const MachineType m = MachineType::from_description(*builtin_machine(name));
    const realtime::Model rt = every_term(m, rng);
    realtime::State s;
    s.y1 = 0.3;
    s.y2 = 0.1;
    s.tool_length = m.has_head() ? m.description().tool_length : 0.0;
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<realtime::Joints> poses(4096);
    for (realtime::Joints& q : poses) {
      q.xyz = Eigen::Vector3d(200 * u(rng), 150 * u(rng), 60 * u(rng));
      q.angles = {0.05 + 1.4 * std::abs(u(rng)), 3.1 * u(rng)};
    }
    std::vector<double> fwd(static_cast<std::size_t>(calls)), inv(fwd.size()), wfwd(fwd.size());
    double sink = 0, worst = 0;
    for (long i = 0; i < calls; ++i) {
      const realtime::Joints& q = poses[static_cast<std::size_t>(i) % poses.size()];
      const auto t0 = std::chrono::steady_clock::now();
      const realtime::ToolPose f = realtime::forward(rt, q, s);
      const auto t1 = std::chrono::steady_clock::now();
      const realtime::InverseResult r = realtime::inverse(rt, q, s);
      const auto t2 = std::chrono::steady_clock::now();
      const realtime::Joints w = realtime::forward_world(rt, q, s);
      const auto t3 = std::chrono::steady_clock::now();
      wfwd[static_cast<std::size_t>(i)] = std::chrono::duration<double, std::nano>(t3 - t2).count();
      sink += w.angles.rot;
      fwd[static_cast<std::size_t>(i)] = std::chrono::duration<double, std::nano>(t1 - t0).count();
      inv[static_cast<std::size_t>(i)] = std::chrono::duration<double, std::nano>(t2 - t1).count();
      sink += f.tip.x();
      worst = std::max(worst, r.tip_error);
    }
    const Times tf = summarise(fwd), ti = summarise(inv), tw = summarise(wfwd);
    std::printf("%-16s %8d %10.3f %10.3f  %10.3f %10.3f %14.2e  %10.3f %10.3f\n", name,
                rt.num_effects, tf.median_us, tf.p999_us, ti.median_us, ti.p999_us, worst * 1e3,
                tw.median_us, tw.p999_us);
    if (sink == 42.0) std::printf(" ");  // keeps the forward calls
  }
  return 0;
}
