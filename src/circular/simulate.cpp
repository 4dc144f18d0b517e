// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/circular/simulate.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/noise_model.hpp"

namespace rotacal {

namespace {

void check_sim(bool ok, const std::string& what) {
  if (!ok) throw InvalidArgument("circular simulation: " + what);
}

double sign_of(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// Actual machine-axis positions (mm) of the run's reading at time t, before the geometric
// errors: servo lag, backlash and reversal spikes of the two moving axes.
Eigen::Vector3d moving_axes(const CircularTestPlan& plan, const CircularRun& run,
                            const LinearAxisErrors& e, const Eigen::Vector3d& centre_axes,
                            double t) {
  const auto ax = plane_axes(run.plane);
  const double theta = run.angle_at(t) * kPi / 180.0;
  const double w = run.omega_rad_s();
  Eigen::Vector3d a = centre_axes;
  for (int j = 0; j < 2; ++j) {
    const int i = ax[static_cast<std::size_t>(j)];
    const double phi = j == 0 ? 0.0 : kPi / 2.0;
    const double tau = e.servo_tau[i];
    const double lag = std::atan(w * tau);
    const double gain = 1.0 / std::sqrt(1.0 + w * w * tau * tau);
    const double psi = theta - lag - phi;  // the axis follows R cos(psi)
    a[i] += plan.radius * gain * std::cos(psi);
    // Direction of travel of the axis; 0 at the turning point itself (|sin psi| < 1e-9: a
    // reading exactly at the reversal), where the lost motion is half taken up.
    const double s = std::abs(std::sin(psi)) < 1e-9 ? 0.0 : sign_of(-std::sin(psi) * w);
    a[i] -= 0.5 * e.backlash[i] * s;
    if (e.spike[i] != 0.0) {
      // Angle travelled since the axis last reversed (psi a multiple of pi).
      const double since = std::fmod(std::fmod(w > 0.0 ? psi : -psi, kPi) + kPi, kPi);
      const double dt = since / std::abs(w);
      if (t - dt >= run.t_start) a[i] -= e.spike[i] * s * std::exp(-dt / e.spike_tau[i]);
    }
  }
  return a;
}

// Geometric errors of the axes at positions a (mm).
Eigen::Vector3d geometric(const LinearAxisErrors& e, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& centre_axes) {
  Eigen::Vector3d p = a;
  p.x() += e.squareness[0] * a.y();
  p.y() += e.squareness[1] * a.z();
  p.z() += e.squareness[2] * a.x();
  for (int i = 0; i < 3; ++i) {
    p[i] += e.scale[i] * a[i];
    const double q = 2.0 * kPi * a[i] / e.screw_pitch[i];
    p[i] += e.cyclic_cos[i] * std::cos(q) + e.cyclic_sin[i] * std::sin(q);
    for (int A = 0; A < 3; ++A) {
      const double u = (a[A] - centre_axes[A]) / 100.0;
      p[i] += e.straightness(i, A) * u * u;
    }
  }
  return p;
}

}  // namespace

void check_circular_simulation(const CircularSimulationOptions& o) {
  const LinearAxisErrors& e = o.errors;
  check_sim(e.squareness.allFinite() && e.scale.allFinite() && e.straightness.allFinite() &&
                e.backlash.allFinite() && e.spike.allFinite() && e.spike_tau.allFinite() &&
                e.servo_tau.allFinite() && e.cyclic_cos.allFinite() && e.cyclic_sin.allFinite() &&
                e.screw_pitch.allFinite(),
            "errors: every value must be finite");
  check_sim(e.straightness.diagonal().isZero(0.0),
            "errors.straightness: the diagonal (an axis' error along itself) must be 0");
  check_sim((e.screw_pitch.array() > 0.0).all(), "errors.screw_pitch must be positive");
  check_sim((e.spike_tau.array() > 0.0).all(), "errors.spike_tau must be positive");
  check_sim((e.servo_tau.array() >= 0.0).all() && (e.servo_tau.array() < 10.0).all(),
            "errors.servo_tau must be in [0, 10) s");
  check_sim(o.centring_error.allFinite() && o.centring_error.cwiseAbs().maxCoeff() <= 10.0,
            "centring_error must be within +-10 mm");
  check_sim(std::isfinite(o.length_error) && std::abs(o.length_error) <= 10.0,
            "length_error must be within +-10 mm");
  check_sim(std::isfinite(o.noise_um) && o.noise_um >= 0.0 && o.noise_um <= 1000.0,
            "noise_um must be in [0, 1000]");
  check_sim(std::isfinite(o.noise_rho) && o.noise_rho >= 0.0 && o.noise_rho < 1.0,
            "noise_rho must be in [0, 1)");
}

// Reading (mm, noise-free) of the bar on the plan's machine: ball at actual axes `a`.
double CircularBar::reading(const Eigen::Vector3d& a) const {
  const Eigen::Vector3d ball = geometric(options.errors, a, centre_axes) + tool;
  return (ball - pivot).norm() + options.length_error;
}

CircularBar::CircularBar(const CircularTestPlan& plan, const CircularSimulationOptions& o)
    : options(o),
      tool(tool_vector<double>(plan.machine, 0.0)),
      centre_axes(plan.centre - tool),
      pivot(plan.centre + o.centring_error) {}

double circular_exact_reading(const CircularTimeline& timeline, const CircularBar& bar, double t) {
  const CircularTimeline::Position p = timeline.position(t);
  const CircularTestPlan& plan = timeline.plan().plan;
  const CircularRun& run = timeline.plan().runs[p.run];
  if (p.on_run) return bar.reading(moving_axes(plan, run, bar.options.errors, bar.centre_axes, t));
  return bar.reading(circular_point(plan, run.plane, p.angle_deg) - bar.tool);
}

BallbarSession simulate_circular(const CircularPlanResult& plan,
                                 const CircularSimulationOptions& o) {
  check_circular_simulation(o);
  BallbarSession session = circular_commanded_session(plan);
  const CircularTestPlan& p = plan.plan;
  const CircularBar bar(p, o);
  std::vector<std::string> groups;
  std::vector<double> times;
  groups.reserve(session.samples.size());
  times.reserve(session.samples.size());
  std::size_t row = 0;
  for (const CircularRun& run : plan.runs)
    for (double t : run.time) {
      BallbarSample& s = session.samples[row++];
      s.length = bar.reading(moving_axes(p, run, o.errors, bar.centre_axes, t));
      groups.push_back(run.label);
      times.push_back(t);
    }
  ROTACAL_ASSERT(row == session.samples.size());
  if (o.noise_um > 0.0) {
    const Eigen::VectorXd n = noise_gen::ar1(groups, times, o.noise_rho, o.noise_um * 1e-3, o.seed);
    for (std::size_t i = 0; i < session.samples.size(); ++i)
      session.samples[i].length += n[static_cast<Eigen::Index>(i)];
  }
  if (o.noise_um > 0.0)
    session.noise_um = o.noise_um;  // noiseless: none declared (a 1-sigma of 0 is refused)
  return session;
}

}  // namespace rotacal
