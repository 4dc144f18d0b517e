// SPDX-License-Identifier: BSD-3-Clause
// Joint fit of a thermal touch-probe session (probe/thermal.hpp).
#include <algorithm>
#include <cmath>

#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/thermal.hpp"

namespace rotacal {

namespace {

const char* kPointGains[3] = {"q_x", "q_y", "q_z"};

// Parameters: location_errors 8 | tool_length (head) | sphere 3 | per lag: ln tau, 11 gains.
struct ThermalLayout {
  ParameterLayout all;
  ParameterBlock errors, tool_length, sphere;
  std::vector<ParameterBlock> tau, gains;

  ThermalLayout(MachineType m, char axis, int lags) {
    errors = add_location_errors(all, m);
    tool_length = all.add(
        "tool_length",
        m.has_head() ? std::vector<std::string>{"tool_offset_Z"} : std::vector<std::string>{},
        {"mm"});
    sphere = all.add("sphere", {"sphere.x", "sphere.y", "sphere.z"}, {"mm"});
    const std::vector<std::string> eu = all.units();
    for (int l = 0; l < lags; ++l) {
      const std::string lag =
          std::string("thermal_location_") + axis + ".lag" + std::to_string(l + 1);
      tau.push_back(all.add(lag + ".tau", {lag + ".ln_tau_300s"}, {"1"}));
      std::vector<std::string> names, units;
      for (int k = 0; k < 8; ++k) {
        names.push_back(lag + ".K." + location_error_names(m)[static_cast<std::size_t>(k)]);
        units.push_back(eu[static_cast<std::size_t>(errors.offset + k)]);
      }
      for (const char* q : kPointGains) names.push_back(lag + ".K." + q), units.push_back("mm");
      gains.push_back(all.add(lag + ".gains", names, units));
    }
  }
};

char duty_axis(const ThermalTest& th) {
  const std::vector<char> axes = th.axes();
  if (axes.size() > 1)
    throw InvalidArgument("thermal identification: the duty turns " + std::to_string(axes.size()) +
                          " axes; one thermal_location_R at a time is supported");
  return axes.empty() ? 0 : axes.front();
}

class ThermalProbeModel : public ResidualModel {
 public:
  ThermalProbeModel(const ProbeSession& s, const ThermalTest& th, int lags)
      : m_(s.machine),
        axis_(duty_axis(th)),
        L_(s.machine, axis_ ? axis_ : rot_axis_letter(s.machine), lags),
        touches_(probe_touches(s)),
        radius_(s.trigger_radius()),
        heat_(th.heat_input(axis_)) {
    if (th.epoch.size() != touches_.size())
      throw InvalidArgument("thermal identification: the thermal test has " +
                            std::to_string(th.epoch.size()) + " rows for " +
                            std::to_string(touches_.size()) + " touches");
  }
  const ThermalLayout& layout() const { return L_; }
  char axis() const { return axis_; }
  Eigen::Index num_residuals() const override { return static_cast<Eigen::Index>(touches_.size()); }
  int num_parameters() const override { return static_cast<int>(L_.all.size()); }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    const EffectModel none;
    const auto one = [&](Eigen::Index i, const auto* p, auto* out) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      const ProbeTouch& t = touches_[static_cast<std::size_t>(i)];
      LocationErrors<T> e = LocationErrors<T>::from_ptr(L_.errors.ptr(p));
      const T* q = L_.sphere.ptr(p);
      Vec3<T> sphere(q[0], q[1], q[2]);
      for (std::size_t l = 0; l < L_.tau.size(); ++l) {
        const T* g = L_.gains[l].ptr(p);
        ThermalGains<T> k;
        k.errors = Eigen::Map<const Eigen::Matrix<T, 8, 1>>(g);
        k.point = Vec3<T>(g[8], g[9], g[10]);
        // Rows come in order within a pass (evaluate_with_jets): one tracker per lag and
        // scalar type continues from the previous row.
        static thread_local LagTracker<T> track[2];
        const T y =
            track[l].at(static_cast<long>(i), heat_, t.time, thermal_tau<T>(L_.tau[l].ptr(p)[0]));
        e = drifted_errors<T>(e, k, y);
        sphere = drifted_point<T>(sphere, k, y);
      }
      const T tool = L_.tool_length.empty() ? T(0) : T(-L_.tool_length.ptr(p)[0]);
      out[0] =
          touch_residual<T>(m_, e, none, static_cast<const T*>(nullptr), sphere, t, radius_, tool);
    };
    evaluate_with_jets(one, num_residuals(), 1, x, r, J);
  }

 private:
  MachineType m_;
  char axis_;
  ThermalLayout L_;
  std::vector<ProbeTouch> touches_;
  double radius_;
  HeatInput heat_;
};

}  // namespace

Eigen::VectorXd thermal_probe_residuals(const ProbeSession& session, const ThermalTest& thermal,
                                        int lags, const Eigen::VectorXd& x) {
  const ThermalProbeModel model(session, thermal, lags);
  Eigen::VectorXd r(model.num_residuals());
  model.evaluate(x, r, nullptr);
  return r;
}

ThermalIdentification identify_thermal_probe(const ProbeSession& session,
                                             const ThermalTest& thermal,
                                             const ThermalFitOptions& options) {
  const ThermalProbeModel model(session, thermal, std::max(1, std::min(2, options.lags)));
  const ThermalLayout& L = model.layout();
  std::vector<FitParameter> params;
  const std::vector<std::string> names = L.all.names(), units = L.all.units();
  for (Eigen::Index j = 0; j < L.all.size(); ++j)
    params.push_back({names[static_cast<std::size_t>(j)], units[static_cast<std::size_t>(j)], 0.0});
  for (int k = 0; k < 3; ++k)
    params[static_cast<std::size_t>(L.sphere.offset + k)].start = session.sphere[k];
  ThermalFitIndex index;
  const auto& enames = location_error_names(session.machine);
  for (int k = 0; k < 11; ++k) {
    const bool e = k < 8;
    index.cold.push_back(static_cast<int>(e ? L.errors.offset + k : L.sphere.offset + k - 8));
    index.cold_names.push_back(e ? enames[static_cast<std::size_t>(k)]
                                 : std::string("sphere.") + "xyz"[k - 8]);
    index.gain_names.push_back(e ? enames[static_cast<std::size_t>(k)] : kPointGains[k - 8]);
    index.gain_cold.push_back(k);
  }
  for (std::size_t l = 0; l < L.tau.size(); ++l) {
    index.tau.push_back(static_cast<int>(L.tau[l].offset));
    index.gains.push_back(static_cast<int>(L.gains[l].offset));
  }
  JointFitSettings settings;
  settings.max_iterations = options.max_iterations;
  settings.observability_min_chi2 = options.observability_min_chi2;
  settings.sigma = session.noise_um.value_or(1.0) * 1e-3;  // scales chi-square only
  const bool heated = model.axis() != 0;
  const NoiseFit nf = fit_thermal(model, params, index, heated, settings,
                                  std::vector<std::string>(session.samples.size(), "touches"),
                                  thermal.time, options);
  ThermalIdentification out = thermal_identification(nf, index, heated);
  out.machine = session.machine;
  out.axis = model.axis();
  out.tested_speed_rpm = heated ? thermal.tested_speed(out.axis) : 0.0;
  out.n_samples = session.samples.size();
  out.n_epochs = thermal.epoch_spans().size();
  return out;
}

}  // namespace rotacal
