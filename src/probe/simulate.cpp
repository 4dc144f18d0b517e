// SPDX-License-Identifier: BSD-3-Clause
// Touch-probe simulator: the touch geometry of formats.md through probe/touch_model.hpp.
#include "rotacal/probe/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/probe/touch_model.hpp"

namespace rotacal {

namespace {

std::string fmt4(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

// Where the stylus triggers moving from x0 along n: Newton on touch_residual(lambda) = 0 from
// lambda = -R (the stylus reaching the nominal sphere), the derivative by a forward difference.
double trigger_lambda(MachineType m, const MachineModel& truth, const EffectModel& fx,
                      const Eigen::Vector3d& q, ProbeTouch t, const Eigen::Vector3d& x0,
                      double radius) {
  double lambda = -radius;
  const auto f = [&](double l) {
    t.xyz = x0 + l * t.n;
    // The trigger itself: the latched position without the lobing shift, applied after.
    const Eigen::Vector3d d =
        table_point<double>(m, truth.errors, fx, truth.effect_data(), t.angles, t.time, q);
    const Eigen::Vector3d tip =
        tool_position<double>(m, truth.errors, fx, truth.effect_data(), t.xyz, t.angles, t.time);
    return (tip - d).norm() - (radius + stylus_radius_error<double>(fx, truth.effect_data()));
  };
  for (int it = 0; it < 30; ++it) {
    const double f0 = f(lambda), h = 1e-6;
    const double slope = (f(lambda + h) - f0) / h;
    if (!(std::abs(slope) > 1e-3))
      throw InvalidArgument("simulate_probe: the approach along (" + fmt4(t.n.x()) + ", " +
                            fmt4(t.n.y()) + ", " + fmt4(t.n.z()) + ") grazes or misses the sphere");
    const double step = f0 / slope;
    lambda -= step;
    if (std::abs(step) < 1e-13) break;
  }
  return lambda;
}
}  // namespace

ProbePattern default_probe_pattern(MachineType m) {
  ProbePattern p;
  double t0 = -90.0, t1 = 90.0;
  if (const auto& l = m.description().axis(m.tilt_index()).limits_deg)
    t0 = std::max(t0, (*l)[0]), t1 = std::min(t1, (*l)[1]);
  for (int i = 0; i < 12; ++i) p.poses_deg.push_back({0.0, 30.0 * i});
  int tilts = 0;
  for (int i = 0; i < 13 && tilts < 12; ++i) {
    const double t = t0 + (t1 - t0) * i / 12.0;
    if (std::abs(t) > 1e-9) p.poses_deg.push_back({t, 0.0}), ++tilts;
  }
  const double s = 0.5, c = std::sqrt(3.0) / 2.0;
  p.directions = {{0, 0, -1}, {-c, 0, -s}, {0, -c, -s}, {c, 0, -s}, {0, c, -s}};
  return p;
}

ProbeSimulation simulate_probe(const MachineModel& truth, const ProbeSimOptions& o) {
  truth.validate("simulate_probe: truth");
  const ProbePattern& P = o.pattern;
  if (P.poses_deg.empty() || (P.directions.empty() && P.pose_directions.empty()))
    throw InvalidArgument(
        "simulate_probe: options.pattern: poses_deg and directions must not be empty");
  if (!P.pose_directions.empty() && P.pose_directions.size() != P.poses_deg.size())
    throw InvalidArgument(
        "simulate_probe: options.pattern: pose_directions must hold one list per pose");
  for (const auto& d : P.pose_directions)
    if (d.empty())
      throw InvalidArgument("simulate_probe: options.pattern: a pose without approach directions");
  if (!(o.noise_um >= 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("simulate_probe: options.noise_um must be >= 0");
  if (!(std::abs(o.ar1_rho) < 1.0))
    throw InvalidArgument("simulate_probe: options.ar1_rho must be in (-1, 1)");
  if (!(P.sphere_diameter > 0.0) || !(P.stylus_diameter >= 0.0))
    throw InvalidArgument(
        "simulate_probe: options.pattern: sphere_diameter must be > 0 and stylus_diameter >= 0");
  const MachineType m = truth.machine;
  if (o.thermal) {
    double last = 0.0;  // the pattern's last touch after its first
    for (std::size_t k = 0; k < P.poses_deg.size(); ++k)
      last = std::max(last, static_cast<double>(k) * P.pose_dt_s +
                                static_cast<double>(P.directions_at(k).size() - 1) * P.touch_dt_s);
    o.thermal->validate(m, last, "simulate_probe: options.thermal");
  }
  ProbeSimulation out;
  out.sphere_actual = P.sphere + o.sphere_offset;
  ProbeSession& s = out.session;
  s.machine = m;
  s.sphere = P.sphere;
  s.sphere_diameter = P.sphere_diameter;
  s.stylus_diameter = P.stylus_diameter;
  if (o.noise_um > 0.0) s.noise_um = o.noise_um;
  s.metadata = {
      {"format", "rotacal-probe/1"},
      {"machine", to_string(m)},
      {"units", "mm, deg, s"},
      {"sphere", fmt4(P.sphere.x()) + ", " + fmt4(P.sphere.y()) + ", " + fmt4(P.sphere.z())},
      {"sphere_diameter", fmt4(P.sphere_diameter)},
      {"stylus_diameter", fmt4(P.stylus_diameter)}};
  const double radius = s.trigger_radius();
  // The touches: nominal start x0 (the tip at the nominal centre), direction and time.
  std::vector<ProbeTouch> touches;
  std::vector<Eigen::Vector3d> x0;
  std::vector<std::size_t> pose_of;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  // A thermal test repeats the pattern at each epoch's start (pose numbers run on).
  const std::vector<double> epoch_start =
      o.thermal ? o.thermal->epoch_start_s : std::vector<double>{0.0};
  const std::size_t n_poses = P.poses_deg.size();
  std::vector<int> epoch_of;
  for (std::size_t kk = 0; kk < n_poses * epoch_start.size(); ++kk) {
    const std::size_t k = kk % n_poses, e = kk / n_poses;
    const RotaryAngles<double> a{P.poses_deg[k].tilt * kDeg, P.poses_deg[k].rot * kDeg};
    const Eigen::Vector3d start = inverse(m, LocationErrors<double>(), a, P.sphere).xyz;
    // A sphere the machine cannot reach (a description's travel) is no session it could take.
    if (const auto& travel = m.description().travel_mm)
      for (int ax = 0; ax < 3; ++ax)
        if (start[ax] < (*travel)(ax, 0) - 1e-9 || start[ax] > (*travel)(ax, 1) + 1e-9)
          throw InvalidArgument("simulate_probe: the sphere at " + fmt4(P.sphere.x()) + ", " +
                                fmt4(P.sphere.y()) + ", " + fmt4(P.sphere.z()) +
                                " mm is outside the machine's travel at pose " +
                                std::to_string(k + 1) + " (" + fmt4(P.poses_deg[k].tilt) + ", " +
                                fmt4(P.poses_deg[k].rot) + " deg): " + std::string(1, "XYZ"[ax]) +
                                " " + fmt4(start[ax]) + " mm, travel " + fmt4((*travel)(ax, 0)) +
                                ".." + fmt4((*travel)(ax, 1)));
    const std::vector<Eigen::Vector3d>& dirs = P.directions_at(k);
    for (std::size_t j = 0; j < dirs.size(); ++j) {
      if (!(dirs[j].norm() > 0.0))
        throw InvalidArgument("simulate_probe: options.pattern: a zero direction");
      ProbeTouch t;
      t.n = dirs[j].normalized();
      t.angles = a;
      t.n_spindle = spindle_frame_direction(m, a, t.n);
      t.time = epoch_start[e] + static_cast<double>(k) * P.pose_dt_s +
               static_cast<double>(j) * P.touch_dt_s;
      touches.push_back(t);
      x0.push_back(start);
      pose_of.push_back(kk);
      epoch_of.push_back(static_cast<int>(e) + 1);
      mean += start - radius * t.n;
    }
  }
  // effects.md: the linear-axis polynomials about the session's mean commanded position.
  EffectModel fx = truth.effects;
  if (!fx.linear_reference) fx.linear_reference = mean / static_cast<double>(touches.size());
  std::vector<std::string> groups(3 * touches.size(), "touches");
  std::vector<double> times;
  for (const ProbeTouch& t : touches) times.insert(times.end(), 3, t.time);
  const Eigen::VectorXd noise = noise_gen::ar1(groups, times, o.ar1_rho, o.noise_um * 1e-3, o.seed);
  // The drift: each touch on the machine and sphere of its lag states (session/thermal_test).
  std::vector<std::vector<double>> states;
  if (o.thermal) {
    std::vector<double> row_time;
    for (const ProbeTouch& t : touches) row_time.push_back(t.time);
    out.thermal = o.thermal->test(row_time, epoch_of);
    states = o.thermal->lag_states(out.thermal);
  }
  MachineModel now = truth;
  for (std::size_t i = 0; i < touches.size(); ++i) {
    const ProbeTouch& t = touches[i];
    Eigen::Vector3d q = out.sphere_actual;
    if (o.thermal) {
      now.errors = o.thermal->errors_at(truth.errors, states, i);
      q = o.thermal->point_at(q, states, i);
    }
    const double lambda = trigger_lambda(m, now, fx, q, t, x0[i], radius);
    ProbeSample r;
    r.pose = std::to_string(pose_of[i] + 1);
    r.time = t.time;
    r.tilt_deg = P.poses_deg[pose_of[i] % n_poses].tilt;
    r.rot_deg = P.poses_deg[pose_of[i] % n_poses].rot;
    r.n = t.n;
    r.xyz = x0[i] + (lambda + lobing_shift<double>(fx, truth.effect_data(), t.n_spindle)) * t.n +
            noise.segment<3>(3 * static_cast<Eigen::Index>(i));
    s.samples.push_back(r);
  }
  return out;
}

}  // namespace rotacal
