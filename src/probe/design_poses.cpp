// SPDX-License-Identifier: BSD-3-Clause
// The touch probe's candidates for the design engine (design_poses.hpp).
#include "design_poses.hpp"

#include <algorithm>
#include <cmath>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/design/format.hpp"

namespace rotacal::probe_design {

std::array<double, 2> tilt_range(MachineType m) {
  std::array<double, 2> t = {-90.0, 90.0};
  if (const auto& l = m.description().axis(m.tilt_index()).limits_deg)
    t = {std::max(t[0], (*l)[0]), std::min(t[1], (*l)[1])};
  return t;
}

std::vector<RotaryAngles<double>> pose_grid(MachineType m, double tilt_step, double rot_step) {
  const std::array<double, 2> t = tilt_range(m);
  std::array<double, 2> r = {0.0, 360.0};
  const auto& rl = m.description().axis(m.rot_index()).limits_deg;
  if (rl) r = *rl;
  // Each candidate pose holds its touches' Jacobian rows in the design: a grid beyond the cap
  // would exhaust the memory (a 0.01 deg tilt step: ~300,000 poses), so it is refused first.
  const double count =
      (std::floor((t[1] - t[0]) / tilt_step) + 2.0) * (std::floor((r[1] - r[0]) / rot_step) + 2.0);
  if (count > kMaxGridPoses)
    throw InvalidArgument("design probe: --tilt-step " + fixed_text(tilt_step, 3) +
                          " and --rot-step " + fixed_text(rot_step, 3) + " deg make ~" +
                          fixed_text(count, 0) + " candidate poses, more than the " +
                          std::to_string(kMaxGridPoses) +
                          " a design holds in bounded memory: coarsen the steps");
  std::vector<double> tilts, rots;
  for (int k = 0; t[0] + k * tilt_step <= t[1] + 1e-9; ++k) tilts.push_back(t[0] + k * tilt_step);
  if (t[1] - tilts.back() > 1e-9) tilts.push_back(t[1]);
  for (int k = 0; r[0] + k * rot_step < r[1] - 1e-9 || (rl && r[0] + k * rot_step <= r[1] + 1e-9);
       ++k)
    rots.push_back(r[0] + k * rot_step);
  std::vector<RotaryAngles<double>> out;
  for (double tilt : tilts)
    for (double rot : rots) out.push_back({tilt, rot});
  return out;
}

std::vector<Eigen::Vector3d> contact_directions(MachineType m, const RotaryAngles<double>& pose_deg,
                                                double max_angle_deg, double step_deg) {
  const RotaryAngles<double> a{pose_deg.tilt * kDeg, pose_deg.rot * kDeg};
  const Eigen::Matrix3d R = m.has_head() ? head_pose<double>(m, LocationErrors<double>(), a).R
                                         : Eigen::Matrix3d::Identity().eval();
  std::vector<double> polar;
  for (int k = 0; k * step_deg < max_angle_deg - 1e-9; ++k) polar.push_back(k * step_deg);
  polar.push_back(max_angle_deg);
  std::vector<Eigen::Vector3d> out;
  for (double th : polar)
    for (int k = 0; k < (th > 0.0 ? 8 : 1); ++k) {
      const double phi = 45.0 * k * kDeg, t = th * kDeg;
      const Eigen::Vector3d contact(std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi),
                                    std::cos(t));
      out.push_back(-(R * contact));  // the stylus moves against the contact normal
    }
  return out;
}

std::vector<RotaryAngles<double>> plannable_poses(MachineType m, const ProbePattern& P,
                                                  double tilt_step, double rot_step,
                                                  const ProbeProgramOptions& program,
                                                  std::vector<std::string>* refused) {
  std::vector<RotaryAngles<double>> out;
  for (const RotaryAngles<double>& pose : pose_grid(m, tilt_step, rot_step)) {
    ProbePattern one = P;
    one.poses_deg = {pose};
    try {
      probe_moves(m, one, program);
      out.push_back(pose);
    } catch (const InvalidArgument& e) {
      if (refused)
        refused->push_back("tilt " + fixed_text(pose.tilt, 1) + ", rotary " +
                           fixed_text(pose.rot, 1) + " deg: " + e.what());
    }
  }
  return out;
}

ProbeSession nominal_touches(MachineType m, const ProbePattern& P, double t0) {
  ProbeSimOptions so;
  so.pattern = P;
  so.noise_um = 0.0;
  ProbeSession s = simulate_probe(MachineModel::nominal(m), so).session;
  for (ProbeSample& x : s.samples) x.time += t0;
  return s;
}

Eigen::MatrixXd start_jacobian(const ProbeSession& session, const EffectModel& fx) {
  const ProbeProblem problem(session, fx);
  const std::vector<FitParameter> params = problem.parameters();
  Eigen::VectorXd x(problem.num_parameters());
  for (std::size_t j = 0; j < params.size(); ++j) x[static_cast<Eigen::Index>(j)] = params[j].start;
  Eigen::VectorXd r(problem.num_residuals());
  Eigen::MatrixXd J(problem.num_residuals(), problem.num_parameters());
  problem.evaluate(x, r, &J);
  return J;
}

}  // namespace rotacal::probe_design
