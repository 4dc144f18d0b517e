// SPDX-License-Identifier: BSD-3-Clause
// Monte Carlo of the joint fits' 1-sigma on coloured noise (issue 11 item 1): empirical sigma
// over noise draws / reported sigma, per location error, ballbar and R-test, with the noise
// model (GLS) and with the noise treated as white; then the RMS z measurement.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <string>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {

struct Noise {
  std::string name;
  double rho;  // < 0: 1/f-like
};

// Per location error: values and reported sigmas over the draws, for one fit mode.
struct Spread {
  std::vector<std::vector<double>> v, s;
  Spread() : v(8), s(8) {}
  template <typename Id>
  void add(const Id& id, MachineType m) {
    const auto& names = location_error_names(m);
    for (int j = 0; j < 8; ++j) {
      const ParameterEstimate& p = id.parameter(names[static_cast<std::size_t>(j)]);
      if (!p.observable) continue;
      v[static_cast<std::size_t>(j)].push_back(p.value);
      s[static_cast<std::size_t>(j)].push_back(p.std);
    }
  }
  // empirical sd / RMS reported sigma, per error (NaN-free: errors never observable skipped)
  std::vector<std::pair<std::string, double>> ratios(MachineType m) const {
    std::vector<std::pair<std::string, double>> out;
    for (std::size_t j = 0; j < 8; ++j) {
      const std::size_t n = v[j].size();
      if (n < 2) continue;
      double mean = 0, var = 0, rep = 0;
      for (double x : v[j]) mean += x;
      mean /= static_cast<double>(n);
      for (double x : v[j]) var += (x - mean) * (x - mean);
      for (double x : s[j]) rep += x * x;
      out.emplace_back(location_error_names(m)[j], std::sqrt(var / static_cast<double>(n - 1)) /
                                                       std::sqrt(rep / static_cast<double>(n)));
    }
    return out;
  }
};

void print(const char* instrument, const Noise& nz, const Spread& a, const Spread& w, MachineType m,
           int draws, double seconds) {
  const auto ra = a.ratios(m), rw = w.ratios(m);
  double lo = 1e9, hi = 0, lw = 1e9, hw = 0;
  std::printf("%-8s %-10s draws %d (%.1f s)\n  noise model:", instrument, nz.name.c_str(), draws,
              seconds);
  for (const auto& r : ra)
    std::printf(" %s %.2f", r.first.c_str(), r.second), lo = std::min(lo, r.second),
                                                        hi = std::max(hi, r.second);
  std::printf("\n  as white:   ");
  for (const auto& r : rw)
    std::printf(" %s %.2f", r.first.c_str(), r.second), lw = std::min(lw, r.second),
                                                        hw = std::max(hw, r.second);
  std::printf("\n  empirical/reported sigma: noise model %.2f-%.2f%s, white %.2f-%.2f\n", lo, hi,
              nz.rho >= 0 ? (lo >= 0.7 && hi <= 1.4 ? " (in 0.7-1.4)" : " (OUTSIDE 0.7-1.4)")
                          : " (1/f: reported)",
              lw, hw);
}

Eigen::VectorXd coloured(const Noise& nz, const std::vector<std::string>& g,
                         const std::vector<double>& t, double sigma_mm, std::uint64_t seed) {
  return nz.rho < 0 ? noise_gen::pink(g, t, sigma_mm, seed)
                    : noise_gen::ar1(g, t, nz.rho, sigma_mm, seed);
}

}  // namespace

int main(int argc, char** argv) {
  int draws = 200;
  bool rtest = true, ballbar = true, pooled = false, bias = true, oracle = false, reml = true;
  double walk_um = 0.1;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke"))
      draws = 3;  // that it runs: the fewest a sigma is a figure of
    else if (!std::strcmp(argv[i], "--draws") && i + 1 < argc)
      draws = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-rtest"))
      rtest = false;
    else if (!std::strcmp(argv[i], "--no-ballbar"))
      ballbar = false;
    else if (!std::strcmp(argv[i], "--pooled"))
      pooled = true;  // one AR model for all streams
    else if (!std::strcmp(argv[i], "--no-bias-factor"))
      bias = false;
    else if (!std::strcmp(argv[i], "--oracle"))
      oracle = true;  // R-test: GLS under the true covariance
    else if (!std::strcmp(argv[i], "--no-reml"))
      reml = false;  // R-test: Burg AR(p) x bias factor (before)
    else if (!std::strcmp(argv[i], "--walk") && i + 1 < argc)
      walk_um = std::atof(argv[++i]);  // R-test probe-zero step per pose, um
    else {
      std::fprintf(
          stderr,
          "usage: noise_mc_bench [--draws N] [--smoke] [--no-rtest] [--no-ballbar] [--pooled] "
          "[--no-bias-factor] [--oracle] [--no-reml] [--walk UM]\n");
      return 2;
    }
  }
  const std::vector<Noise> kinds = {
      {"AR(0.5)", 0.5}, {"AR(0.9)", 0.9}, {"AR(0.95)", 0.95}, {"1/f-like", -1}};
  using clock = std::chrono::steady_clock;

  // Ballbar: Flynn et al.'s Table 2 machine on the shared session's poses, 0.5 um marginal.
  const BallbarSession cmd =
      read_ballbar(std::string(ROTACAL_SHARED_DIR) + "/data/ballbar_ac_table2.csv");
  BallbarMachineModel truth;
  truth.machine = MachineType::AC_trt;
  std::mt19937 rng(2016);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int i = 0; i < 8; ++i)
    truth.errors.v[i] = location_error_is_angle(i) ? 5e-5 * N(rng) : 0.03 * N(rng);
  truth.pivot = cmd.pivot + Eigen::Vector3d(0.01, -0.02, 0.015);
  const BallbarSession clean = simulate_ballbar(cmd, truth, {0.0, 1, false});
  std::vector<std::string> g;
  std::vector<double> t;
  for (const BallbarSample& x : clean.samples) g.push_back(x.test), t.push_back(x.time);
  JointFitOptions white;
  white.noise.noise = NoiseHandling::white;
  JointFitOptions automatic;
  automatic.noise.noise = NoiseHandling::automatic;
  automatic.noise.noise_options.pooled = pooled;
  automatic.noise.noise_bias_correction = bias;
  for (const Noise& nz : kinds) {
    if (!ballbar) break;
    const auto t0 = clock::now();
    Spread a, w;
    for (int k = 0; k < draws; ++k) {
      BallbarSession s = clean;
      const Eigen::VectorXd e = coloured(nz, g, t, 0.5e-3, 1000 + static_cast<std::uint64_t>(k));
      for (std::size_t i = 0; i < s.samples.size(); ++i)
        s.samples[i].length += e[static_cast<Eigen::Index>(i)];
      s.noise_um = 0.5;
      a.add(identify_joint(s, automatic), MachineType::AC_trt);
      w.add(identify_joint(s, white), MachineType::AC_trt);
    }
    print("ballbar", nz, a, w, MachineType::AC_trt, draws,
          std::chrono::duration<double>(clock::now() - t0).count());
  }

  // R-test: 0.3 um coloured noise per probe channel plus probe zeros that wander between poses
  // (random walk, --walk um per pose, 0.1 by default).
  if (rtest) {
    MachineModel rt = MachineModel::nominal(MachineType::BC_trt);
    rt.machine = MachineType::BC_trt;
    for (int i = 0; i < 8; ++i)
      rt.errors.v[i] = location_error_is_angle(i) ? 3e-5 * N(rng) : 0.02 * N(rng);
    RtestSimOptions so;
    so.noise_um = 0.0;
    const RtestSession rclean = simulate_rtest(rt, so).session;
    std::vector<std::string> rg;
    std::vector<double> rtm;
    for (const RtestSample& x : rclean.samples)
      for (int c = 0; c < 3; ++c) rg.push_back("nest " + x.setup), rtm.push_back(x.time);
    RtestJointOptions rauto;
    rauto.noise.noise = NoiseHandling::automatic;
    rauto.noise.noise_options.pooled = pooled;
    rauto.noise.noise_bias_correction = bias;
    rauto.noise.noise_options.reml_random_walk = reml;
    RtestJointOptions rwhite;
    rwhite.noise.noise = NoiseHandling::white;
    // The generating covariance as a noise model (AR(1) + random walk per stream), for
    // --oracle: the best any estimated noise model can do.
    const auto truth_model = [&](double rho) {
      NoiseModel m;
      m.n = rg.size();
      std::vector<std::string> sg;
      std::vector<int> sc;
      const auto streams = noise_streams(rg, rtm, &sg, &sc);
      for (std::size_t k = 0; k < streams.size(); ++k) {
        NoiseStream st;
        st.group = sg[k], st.channel = sc[k], st.rows = streams[k];
        st.marginal_sigma_um = 0.3;
        st.reflection = {rho};
        st.ar = {rho};
        st.random_walk_step_um = walk_um;
        m.streams.push_back(st);
      }
      m.max_order = 1, m.random_walk_step_um = walk_um;
      return m;
    };
    std::printf("R-test, probe zeros walking %.2f um per pose; noise model: %s\n", walk_um,
                oracle ? "the true covariance (AR(1) rho + the walk; 1/f: as estimated)"
                : reml ? "AR(1) + random walk per stream by REML"
                       : "Burg AR(p) of the residuals x bias factor");
    for (const Noise& nz : kinds) {
      rauto.whitener = nullptr;
      if (oracle && nz.rho >= 0) {
        rauto.noise.noise = NoiseHandling::white;
        rauto.whitener = std::make_shared<ArWhitener>(truth_model(nz.rho));
      }
      const auto t0 = clock::now();
      Spread a, w;
      for (int k = 0; k < draws; ++k) {
        RtestSession s = rclean;
        const Eigen::VectorXd e =
            coloured(nz, rg, rtm, 0.3e-3, 5000 + static_cast<std::uint64_t>(k)) +
            noise_gen::probe_zero_wander(rg, rtm, walk_um * 1e-3,
                                         9000 + static_cast<std::uint64_t>(k));
        for (std::size_t r = 0; r < s.samples.size(); ++r)
          for (int c = 0; c < 3; ++c)
            (*s.samples[r].d)[c] += e[3 * static_cast<Eigen::Index>(r) + c];
        s.noise_um = 0.3;
        a.add(identify_joint(s, rauto), MachineType::BC_trt);
        w.add(identify_joint(s, rwhite), MachineType::BC_trt);
      }
      print("R-test", nz, a, w, MachineType::BC_trt, draws,
            std::chrono::duration<double>(clock::now() - t0).count());
    }
  }

  // The measurement: RMS of (estimate - truth) / sigma over 40 estimates (5 random
  // machines x 8 location errors), AR(0.95) ballbar sessions, 0.5 um marginal.
  double zw = 0, za = 0;
  int n = 0;
  std::mt19937 r2(6);
  for (int k = 0; k < 5; ++k) {
    BallbarMachineModel m;
    m.machine = MachineType::AC_trt;
    for (int i = 0; i < 8; ++i)
      m.errors.v[i] = location_error_is_angle(i) ? 5e-5 * N(r2) : 0.03 * N(r2);
    m.pivot = cmd.pivot;
    BallbarSession s = simulate_ballbar(cmd, m, {0.0, 1, false});
    const Eigen::VectorXd e =
        noise_gen::ar1(g, t, 0.95, 0.5e-3, 77 + static_cast<std::uint64_t>(k));
    for (std::size_t i = 0; i < s.samples.size(); ++i)
      s.samples[i].length += e[static_cast<Eigen::Index>(i)];
    s.noise_um = 0.5;
    const BallbarIdentification a = identify_joint(s, automatic), w = identify_joint(s, white);
    for (int j = 0; j < 8; ++j) {
      const std::string& nm =
          location_error_names(MachineType::AC_trt)[static_cast<std::size_t>(j)];
      const double dz_a = (a.parameter(nm).value - m.errors.v[j]) / a.parameter(nm).std;
      const double dz_w = (w.parameter(nm).value - m.errors.v[j]) / w.parameter(nm).std;
      za += dz_a * dz_a, zw += dz_w * dz_w, ++n;
    }
  }
  std::printf(
      "issue 11 measurement, RMS (estimate - truth)/sigma over %d AR(0.95) ballbar estimates: "
      "as white %.2f, noise model %.2f\n",
      n, std::sqrt(zw / n), std::sqrt(za / n));
  return 0;
}
