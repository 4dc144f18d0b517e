// R-test simulator: the one reading of rtest/model.hpp on a machine model, probe zeros and noise.
#include "rotacal/rtest/simulate.hpp"

#include <Eigen/Dense>
#include <cstdio>
#include <random>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {
constexpr double kDeg = M_PI / 180.0;

std::string fmt(double v, int prec) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}

}  // namespace

RtestSimulation simulate_rtest(const MachineModel& truth, const RtestSimOptions& o) {
  truth.validate("simulate_rtest: truth");
  if (o.pattern.b_deg.empty() || o.pattern.c_deg.empty() || o.pattern.nests.empty())
    throw InvalidArgument("simulate_rtest: options.pattern: b_deg, c_deg and nests must not be empty");
  if (o.noise_um < 0 || o.probe_zero_um < 0)
    throw InvalidArgument("simulate_rtest: options.noise_um and probe_zero_um must be >= 0");
  if (o.probe_dirs && std::abs(o.probe_dirs->determinant()) < 1e-6)
    throw InvalidArgument("simulate_rtest: options.probe_dirs: directions are linearly dependent");
  if (!o.probe_dirs && !o.write_d)
    throw InvalidArgument("simulate_rtest: options.write_d = false needs probe_dirs");

  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_um * 1e-3), zero(0.0, o.probe_zero_um * 1e-3);
  RtestSimulation out;
  RtestSession& s = out.session;
  s.machine = truth.machine;
  s.noise_um = o.noise_um;
  s.metadata = {{"format", "rotacal-rtest/1"}, {"machine", to_string(truth.machine)},
                {"units", "mm, deg, s"}};
  for (std::size_t n = 0; n < o.pattern.nests.size(); ++n) {
    const Eigen::Vector3d& q = o.pattern.nests[n];
    const std::string label = std::to_string(n + 1);
    s.nests[label] = q;
    s.metadata.push_back({"nest." + label, fmt(q.x(), 4) + ", " + fmt(q.y(), 4) + ", " + fmt(q.z(), 4)});
  }
  if (o.probe_dirs)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = o.probe_dirs->row(k).transpose();
      s.probe_dirs[k + 1] = u;
      s.metadata.push_back({"probe." + std::to_string(k + 1) + ".dir",
                            fmt(u.x(), 6) + ", " + fmt(u.y(), 6) + ", " + fmt(u.z(), 6)});
    }
  s.metadata.push_back({"noise_um", fmt(o.noise_um, 4)});

  double t = 0.0;
  for (std::size_t n = 0; n < o.pattern.nests.size(); ++n) {
    const Eigen::Vector3d& q = o.pattern.nests[n];
    const Eigen::Vector3d z(zero(rng), zero(rng), zero(rng));
    out.probe_zeros.push_back(z);
    for (double b : o.pattern.b_deg)
      for (double c : o.pattern.c_deg) {
        RtestSample r;
        r.setup = std::to_string(n + 1);
        r.time = t;
        r.tilt_deg = b;
        r.rot_deg = c;
        const RotaryAngles<double> a{b * kDeg, c * kDeg};
        r.xyz = rtest_commanded_xyz(truth.machine, q, a);
        const Eigen::Vector3d d =
            rtest_reading<double>(truth.machine, truth.errors, truth.effects, truth.effect_data(),
                                  r.xyz, a, t, q) + z;
        const Eigen::Vector3d e(noise(rng), noise(rng), noise(rng));
        if (o.probe_dirs) {
          r.raw = (*o.probe_dirs) * d + e;
          if (o.write_d) r.d = o.probe_dirs->fullPivLu().solve(*r.raw);
        } else {
          r.d = d + e;
        }
        s.samples.push_back(r);
        t += o.pattern.dwell_s;
      }
  }
  return out;
}

}  // namespace rotacal
