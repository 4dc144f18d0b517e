// The touch probe's candidates for the design engine (design_poses.hpp).
#include "design_poses.hpp"

#include <algorithm>
#include <cmath>

#include "rotacal/core/error.hpp"
#include "rotacal/design/format.hpp"

namespace rotacal::probe_design {

std::array<double, 2> tilt_range(MachineType m) {
  std::array<double, 2> t = {-90.0, 90.0};
  if (const auto& l = m.description().axis(m.tilt_index()).limits_deg)
    t = {std::max(t[0], (*l)[0]), std::min(t[1], (*l)[1])};
  return t;
}

std::vector<RotaryAngles<double>> plannable_poses(MachineType m, const ProbePattern& P, double tilt_step,
                                                  double rot_step, const ProbeProgramOptions& program,
                                                  std::vector<std::string>* refused) {
  const std::array<double, 2> t = tilt_range(m);
  std::vector<double> tilts, rots;
  for (int k = 0; t[0] + k * tilt_step <= t[1] + 1e-9; ++k) tilts.push_back(t[0] + k * tilt_step);
  if (t[1] - tilts.back() > 1e-9) tilts.push_back(t[1]);
  std::array<double, 2> r = {0.0, 360.0};
  const auto& rl = m.description().axis(m.rot_index()).limits_deg;
  if (rl) r = *rl;
  for (int k = 0; r[0] + k * rot_step < r[1] - 1e-9 || (rl && r[0] + k * rot_step <= r[1] + 1e-9); ++k)
    rots.push_back(r[0] + k * rot_step);
  std::vector<RotaryAngles<double>> out;
  for (double tilt : tilts)
    for (double rot : rots) {
      ProbePattern one = P;
      one.poses_deg = {{tilt, rot}};
      try {
        probe_moves(m, one, program);
        out.push_back(one.poses_deg[0]);
      } catch (const InvalidArgument& e) {
        if (refused)
          refused->push_back("tilt " + fixed_text(tilt, 1) + ", rotary " + fixed_text(rot, 1) + " deg: " + e.what());
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
