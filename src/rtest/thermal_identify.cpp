// SPDX-License-Identifier: BSD-3-Clause
// Joint fit of a thermal R-test session (rtest/thermal.hpp).
#include <algorithm>
#include <cmath>

#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "rotacal/rtest/model.hpp"
#include "rotacal/rtest/problem.hpp"
#include "rotacal/rtest/thermal.hpp"

namespace rotacal {

namespace {

// Parameters: location_errors 8 | tool_offset_Z (head) | zeros 3 per set-up | per lag: ln tau,
// 8 error gains, 3 gains per nest.
struct ThermalRtestLayout {
  ParameterLayout all;
  ParameterBlock errors, tool, zeros;
  std::vector<ParameterBlock> tau, gains;
  std::vector<std::string> gain_names;

  ThermalRtestLayout(MachineType m, char axis, const std::vector<std::string>& setups, int lags) {
    errors = add_location_errors(all, m);
    tool = all.add(
        "tool_length",
        m.has_head() ? std::vector<std::string>{"tool_offset_Z"} : std::vector<std::string>{},
        {"mm"});
    std::vector<std::string> z;
    for (const std::string& s : setups)
      for (const char* c : {".x", ".y", ".z"}) z.push_back("zero." + s + c);
    zeros = all.add("zeros", z, {"mm"}, 3);
    std::vector<std::string> units = all.units();
    units.resize(static_cast<std::size_t>(errors.offset + 8));
    for (int k = 0; k < 8; ++k)
      gain_names.push_back(location_error_names(m)[static_cast<std::size_t>(k)]);
    for (const std::string& s : setups)
      for (const char* c : {"q_x", "q_y", "q_z"}) {
        gain_names.push_back(setups.size() == 1 ? std::string(c) : std::string(c) + "." + s);
        units.push_back("mm");
      }
    units.erase(units.begin(), units.begin() + errors.offset);
    for (int l = 0; l < lags; ++l) {
      const std::string lag =
          std::string("thermal_location_") + axis + ".lag" + std::to_string(l + 1);
      tau.push_back(all.add(lag + ".tau", {lag + ".ln_tau_300s"}, {"1"}));
      std::vector<std::string> names;
      for (const std::string& g : gain_names) names.push_back(lag + ".K." + g);
      gains.push_back(all.add(lag + ".gains", names, units));
    }
  }
};

class ThermalRtestModel : public ResidualModel {
 public:
  ThermalRtestModel(const RtestSession& s, const ThermalTest& th, char axis, int lags)
      : d_(rtest_arrays(s, "thermal identification")),
        L_(s.machine, axis ? axis : rot_axis_letter(s.machine), d_.setups, lags),
        heat_(th.heat_input(axis)) {}
  const ThermalRtestLayout& layout() const { return L_; }
  const RtestArrays& arrays() const { return d_; }
  Eigen::Index num_residuals() const override { return 3 * d_.size(); }
  int num_parameters() const override { return static_cast<int>(L_.all.size()); }
  Eigen::Index num_items() const override { return d_.size(); }
  int rows_per_item() const override { return 3; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    const EffectModel none;
    const auto one = [&](Eigen::Index i, const auto* p, auto* out) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      const std::size_t k = static_cast<std::size_t>(i);
      const int setup = d_.setup_of[k];
      LocationErrors<T> e = LocationErrors<T>::from_ptr(L_.errors.ptr(p));
      Vec3<T> nest_shift = Vec3<T>::Zero();
      for (std::size_t l = 0; l < L_.tau.size(); ++l) {
        const T* g = L_.gains[l].ptr(p);
        ThermalGains<T> K;
        K.errors = Eigen::Map<const Eigen::Matrix<T, 8, 1>>(g);
        K.point = Vec3<T>(g[8 + 3 * setup], g[9 + 3 * setup], g[10 + 3 * setup]);
        static thread_local LagTracker<T> track[2];  // rows in order: continue (thermal_lag)
        const T y = track[l].at(static_cast<long>(i), heat_, d_.time[k],
                                thermal_tau<T>(L_.tau[l].ptr(p)[0]));
        e = drifted_errors<T>(e, K, y);
        nest_shift = drifted_point<T>(nest_shift, K, y);
      }
      const Vec3<T> d = rtest_reading<T>(d_.machine, e, none, static_cast<const T*>(nullptr),
                                         d_.xyz.col(i), d_.angles[k], d_.time[k], d_.nest.col(i),
                                         L_.tool.empty() ? T(0) : T(-p[L_.tool.offset]));
      const T* zero = p + L_.zeros.item_offset(setup);
      for (int a = 0; a < 3; ++a) out[a] = d[a] - nest_shift[a] + zero[a] - T(d_.d(a, i));
    };
    evaluate_with_jets(one, d_.size(), 3, x, r, J);
  }

 private:
  RtestArrays d_;
  ThermalRtestLayout L_;
  HeatInput heat_;
};

}  // namespace

ThermalIdentification identify_thermal_rtest(const RtestSession& session,
                                             const ThermalTest& thermal,
                                             const ThermalFitOptions& options) {
  const std::vector<char> axes = thermal.axes();
  if (axes.size() > 1)
    throw InvalidArgument("thermal identification: the duty turns " + std::to_string(axes.size()) +
                          " axes; one thermal_location_R at a time is supported");
  if (thermal.epoch.size() != session.samples.size())
    throw InvalidArgument("thermal identification: the thermal test has " +
                          std::to_string(thermal.epoch.size()) + " rows for " +
                          std::to_string(session.samples.size()) + " poses");
  const char axis = axes.empty() ? 0 : axes.front();
  const ThermalRtestModel model(session, thermal, axis, std::max(1, std::min(2, options.lags)));
  const ThermalRtestLayout& L = model.layout();
  std::vector<FitParameter> params;
  const std::vector<std::string> names = L.all.names(), units = L.all.units();
  for (Eigen::Index j = 0; j < L.all.size(); ++j)
    params.push_back({names[static_cast<std::size_t>(j)], units[static_cast<std::size_t>(j)], 0.0});
  ThermalFitIndex index;
  for (int k = 0; k < 8; ++k) {
    index.cold.push_back(static_cast<int>(L.errors.offset + k));
    index.cold_names.push_back(L.gain_names[static_cast<std::size_t>(k)]);
  }
  index.gain_names = L.gain_names;
  for (std::size_t k = 0; k < L.gain_names.size(); ++k)
    index.gain_cold.push_back(k < 8 ? static_cast<int>(k) : -1);
  for (std::size_t l = 0; l < L.tau.size(); ++l) {
    index.tau.push_back(static_cast<int>(L.tau[l].offset));
    index.gains.push_back(static_cast<int>(L.gains[l].offset));
  }
  // formats.md: a nest dismounted between epochs is a set-up per epoch, whose probe zero takes
  // the nest's drift: its gains are held and reported so, not fitted to the decay within one
  // epoch (which would leave them "determined" at +-70 um).
  std::vector<bool> dismounted(model.arrays().setups.size(), false);
  if (axis != 0) {
    std::vector<std::pair<int, int>> span(dismounted.size(), {-1, -1});  // first, last epoch
    for (std::size_t i = 0; i < session.samples.size(); ++i) {
      auto& sp = span[static_cast<std::size_t>(model.arrays().setup_of[i])];
      if (sp.first < 0) sp.first = thermal.epoch[i];
      sp.second = thermal.epoch[i];
    }
    for (std::size_t s = 0; s < dismounted.size(); ++s) {
      dismounted[s] = span[s].first == span[s].second;
      for (std::size_t l = 0; l < L.gains.size() && dismounted[s]; ++l)
        for (int a = 0; a < 3; ++a)
          params[static_cast<std::size_t>(L.gains[l].offset) + 8 + 3 * s + a].held = true;
    }
  }
  JointFitSettings settings;
  settings.max_iterations = options.max_iterations;
  settings.observability_min_chi2 = options.observability_min_chi2;
  settings.sigma = session.noise_um.value_or(1.0) * 1e-3;  // scales chi-square only
  std::vector<std::string> groups;
  std::vector<double> times;
  for (const RtestSample& s : session.samples)
    for (int a = 0; a < 3; ++a) groups.push_back("nest " + s.setup), times.push_back(s.time);
  const bool heated = axis != 0;
  ThermalFitOptions o = options;
  o.noise.allow_reml = true;  // the probe zeros may wander (rtest/identify_joint.cpp)
  const NoiseFit nf = fit_thermal(model, params, index, heated, settings, groups, times, o);
  ThermalIdentification out = thermal_identification(nf, index, heated);
  for (ThermalLag& lag : out.lags)
    for (std::size_t s = 0; s < dismounted.size(); ++s)
      for (int a = 0; a < 3 && dismounted[s]; ++a) {
        ThermalGainEstimate& g = lag.gains[8 + 3 * s + static_cast<std::size_t>(a)];
        g.observable = false;
        g.reason = "the nest of set-up " + model.arrays().setups[s] +
                   " was measured in one epoch only (dismounted between epochs): its probe "
                   "zero takes the nest's drift";
      }
  out.machine = session.machine;
  out.axis = axis;
  out.tested_speed_rpm = heated ? thermal.tested_speed(axis) : 0.0;
  out.n_samples = session.samples.size();
  out.n_epochs = thermal.epoch_spans().size();
  return out;
}

}  // namespace rotacal
