// SPDX-License-Identifier: BSD-3-Clause
// R-test simulator: the one reading of rtest/model.hpp on a machine model, probe zeros and noise.
#include "rotacal/rtest/simulate.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <random>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"

namespace rotacal {

namespace {

std::string format_fixed(double v, int prec) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}

std::string limits_text(const std::array<double, 2>& l) {
  char buf[80];
  std::snprintf(buf, sizeof buf, "[%g, %g]", l[0], l[1]);
  return buf;
}

// First offending commanded X, Y, Z of the nest q over the poses (deg), as text; empty when
// every pose is inside the travel (or the machine gives none).
std::string travel_violation(MachineType m, const Eigen::Vector3d& q,
                             const std::vector<RotaryAngles<double>>& poses) {
  const auto& travel = m.description().travel_mm;
  if (!travel) return "";
  const char* names = "XYZ";
  for (const RotaryAngles<double>& p : poses) {
    const double b = p.tilt, c = p.rot;
    const Eigen::Vector3d xyz = rtest_commanded_xyz(m, q, {b * kDeg, c * kDeg});
    for (int k = 0; k < 3; ++k)
      if (xyz[k] < (*travel)(k, 0) - 1e-9 || xyz[k] > (*travel)(k, 1) + 1e-9)
        return std::string(1, names[k]) + " = " + format_fixed(xyz[k], 3) + " mm at " +
               tilt_axis_letter(m) + " " + format_fixed(b, 3) + ", " + rot_axis_letter(m) + " " +
               format_fixed(c, 3) + " deg is outside the travel [" +
               format_fixed((*travel)(k, 0), 1) + ", " + format_fixed((*travel)(k, 1), 1) + "]";
  }
  return "";
}

}  // namespace

std::vector<RotaryAngles<double>> RtestPattern::poses() const {
  if (!poses_deg.empty()) return poses_deg;
  std::vector<RotaryAngles<double>> out;
  for (double b : b_deg)
    for (double c : c_deg) out.push_back({b, c});
  return out;
}

RtestPattern default_rtest_pattern(MachineType m) {
  const MachineDescription& d = m.description();
  RtestPattern p;
  if (const auto& l = d.axis(m.tilt_index()).limits_deg) {
    const double span = std::min(180.0, (*l)[1] - (*l)[0]);
    const double centre = std::clamp(0.0, (*l)[0] + span / 2, (*l)[1] - span / 2);
    p.b_deg.clear();
    for (int i = 0; i < 7; ++i) p.b_deg.push_back(centre - span / 2 + span * i / 6.0);
  }
  if (const auto& l = d.axis(m.rot_index()).limits_deg) {
    const double span = (*l)[1] - (*l)[0];
    p.c_deg.clear();
    for (int i = 0; i < 12; ++i)
      p.c_deg.push_back(span >= 360.0 ? (*l)[0] + 30.0 * i : (*l)[0] + span * i / 11.0);
  }
  for (std::size_t n = 0; n < p.nests.size(); ++n) {
    Eigen::Vector3d& q = p.nests[n];
    int halvings = 0;
    std::string why;
    while (!(why = travel_violation(m, q, p.poses())).empty() && halvings < 4) q *= 0.5, ++halvings;
    if (!why.empty())
      throw InvalidArgument(
          "default_rtest_pattern: " + to_string(m) + ": nest " + std::to_string(n + 1) +
          " does not fit the travel even at 1/16 of its default position: " + why);
  }
  return p;
}

void check_rtest_pattern(MachineType m, const RtestPattern& pattern, const std::string& context) {
  const MachineDescription& d = m.description();
  const std::vector<RotaryAngles<double>> poses = pattern.poses();
  for (int k : {m.tilt_index(), m.rot_index()}) {
    const RotaryAxis& ax = d.axis(k);
    if (!ax.limits_deg) continue;
    for (const RotaryAngles<double>& p : poses) {
      const double v = k == m.tilt_index() ? p.tilt : p.rot;
      if (v < (*ax.limits_deg)[0] - 1e-9 || v > (*ax.limits_deg)[1] + 1e-9)
        throw InvalidArgument(context + ": " + std::string(1, ax.name) + " " + format_fixed(v, 3) +
                              " deg is beyond its limits " + limits_text(*ax.limits_deg) + " on " +
                              to_string(m) + " (default_rtest_pattern fits the machine)");
    }
  }
  for (std::size_t n = 0; n < pattern.nests.size(); ++n) {
    const std::string why = travel_violation(m, pattern.nests[n], poses);
    if (!why.empty())
      throw InvalidArgument(context + ": nest " + std::to_string(n + 1) + ": " + why + " on " +
                            to_string(m));
  }
}

RtestSimulation simulate_rtest(const MachineModel& truth, const RtestSimOptions& o) {
  truth.validate("simulate_rtest: truth");
  const std::vector<RotaryAngles<double>> poses = o.pattern.poses();
  if (poses.empty() || o.pattern.nests.empty())
    throw InvalidArgument(
        "simulate_rtest: options.pattern: b_deg, c_deg (or poses_deg) and nests must not be empty");
  check_rtest_pattern(truth.machine, o.pattern, "simulate_rtest: options.pattern");
  if (o.noise_um < 0 || o.probe_zero_um < 0)
    throw InvalidArgument("simulate_rtest: options.noise_um and probe_zero_um must be >= 0");
  if (o.probe_dirs && std::abs(o.probe_dirs->determinant()) < 1e-6)
    throw InvalidArgument("simulate_rtest: options.probe_dirs: directions are linearly dependent");
  if (!o.probe_dirs && !o.write_d)
    throw InvalidArgument("simulate_rtest: options.write_d = false needs probe_dirs");
  if (!(std::abs(o.ar1_rho) < 1.0))
    throw InvalidArgument("simulate_rtest: options.ar1_rho must be in (-1, 1)");
  const std::size_t per_epoch = poses.size() * o.pattern.nests.size();
  if (o.thermal)
    o.thermal->validate(truth.machine, o.pattern.dwell_s * static_cast<double>(per_epoch - 1),
                        "simulate_rtest: options.thermal");

  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_um * 1e-3), zero(0.0, o.probe_zero_um * 1e-3);
  RtestSimulation out;
  RtestSession& s = out.session;
  s.machine = truth.machine;
  if (o.noise_um > 0.0)
    s.noise_um = o.noise_um;  // noiseless: none declared (a 1-sigma of 0 is refused)
  s.metadata = {{"format", "rotacal-rtest/1"},
                {"machine", to_string(truth.machine)},
                {"units", "mm, deg, s"}};
  for (std::size_t n = 0; n < o.pattern.nests.size(); ++n) {
    const Eigen::Vector3d& q = o.pattern.nests[n];
    const std::string label = std::to_string(n + 1);
    s.nests[label] = q;
    s.metadata.push_back({"nest." + label, format_fixed(q.x(), 4) + ", " + format_fixed(q.y(), 4) +
                                               ", " + format_fixed(q.z(), 4)});
  }
  if (o.probe_dirs)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = o.probe_dirs->row(k).transpose();
      s.probe_dirs[k + 1] = u;
      s.metadata.push_back(
          {"probe." + std::to_string(k + 1) + ".dir",
           format_fixed(u.x(), 6) + ", " + format_fixed(u.y(), 6) + ", " + format_fixed(u.z(), 6)});
    }
  if (o.noise_um > 0.0) s.metadata.push_back({"noise_um", format_fixed(o.noise_um, 4)});

  // effects.md: the linear-axis polynomials are about the session's mean commanded xyz.
  EffectModel fx = truth.effects;
  if (!fx.linear_reference) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& q : o.pattern.nests)
      for (const RotaryAngles<double>& p : poses)
        sum += rtest_commanded_xyz(truth.machine, q, {p.tilt * kDeg, p.rot * kDeg});
    fx.linear_reference = sum / static_cast<double>(per_epoch);
  }
  // The rows: each nest's poses in turn, once (or once per thermal epoch, every nest mounted
  // through the session), dwell_s apart.
  const std::vector<double> epoch_start =
      o.thermal ? o.thermal->epoch_start_s : std::vector<double>{0.0};
  std::vector<double> row_time;
  std::vector<int> row_epoch;
  std::vector<std::string> groups;
  for (std::size_t e = 0; e < epoch_start.size(); ++e)
    for (std::size_t i = 0; i < per_epoch; ++i) {
      row_time.push_back(epoch_start[e] + o.pattern.dwell_s * static_cast<double>(i));
      row_epoch.push_back(static_cast<int>(e) + 1);
      for (int k = 0; k < 3; ++k)
        groups.push_back(std::to_string(i / poses.size()) + "." + std::to_string(k));
    }
  std::vector<std::vector<double>> states;
  if (o.thermal) {
    out.thermal = o.thermal->test(row_time, row_epoch);
    states = o.thermal->lag_states(out.thermal);
  }
  // Coloured noise: AR(1) per set-up and channel in row order (white draws below when rho = 0).
  std::vector<double> stream_time;
  for (double t : row_time) stream_time.insert(stream_time.end(), 3, t);
  const Eigen::VectorXd ar =
      o.ar1_rho != 0.0 ? noise_gen::ar1(groups, stream_time, o.ar1_rho, o.noise_um * 1e-3, o.seed)
                       : Eigen::VectorXd();
  LocationErrors<double> errors = truth.errors;
  for (std::size_t row = 0; row < row_time.size(); ++row) {
    const std::size_t n = (row % per_epoch) / poses.size();
    const RotaryAngles<double>& p = poses[row % poses.size()];
    Eigen::Vector3d q = o.pattern.nests[n];
    if (o.thermal) {
      errors = o.thermal->errors_at(truth.errors, states, row);
      q = o.thermal->point_at(q, states, row);
    }
    if (n == out.probe_zeros.size()) {  // a nest's first row draws its zero (the draws' order)
      const Eigen::Vector3d z(zero(rng), zero(rng), zero(rng));
      out.probe_zeros.push_back(z);
    }
    const double t = row_time[row];
    RtestSample r;
    r.setup = std::to_string(n + 1);
    r.time = t;
    r.tilt_deg = p.tilt;
    r.rot_deg = p.rot;
    const RotaryAngles<double> a{p.tilt * kDeg, p.rot * kDeg};
    // Commanded at the nominal nest; read against it, the table-side point where it drifted to.
    r.xyz = rtest_commanded_xyz(truth.machine, o.pattern.nests[n], a);
    const Eigen::Vector3d d =
        rtest_reading<double>(truth.machine, errors, fx, truth.effect_data(), r.xyz, a, t, q) +
        out.probe_zeros[n];
    const Eigen::Vector3d e = ar.size() ? Eigen::Vector3d(ar.segment<3>(3 * row))
                                        : Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    if (o.probe_dirs) {
      r.raw = (*o.probe_dirs) * d + e;
      if (o.write_d) r.d = o.probe_dirs->fullPivLu().solve(*r.raw);
    } else {
      r.d = d + e;
    }
    s.samples.push_back(r);
  }
  return out;
}

}  // namespace rotacal
