// SPDX-License-Identifier: BSD-3-Clause
// One lag fitted to per-epoch series (session/thermal_series.hpp).
#include "rotacal/session/thermal_series.hpp"

#include <cmath>

namespace rotacal {

namespace {

// Parameters: the cold values c_k (index k), the gains K_k (n + k), then ln tau (2n).
// Residuals (whitened): (c_k + K_k y(t_e) - v_k(e)) / sigma_k(e) over the determined entries.
class SeriesModel : public ResidualModel {
 public:
  struct Entry {
    int series;
    double t, value, std;
  };
  SeriesModel(std::vector<Entry> entries, std::size_t n_series, HeatInput heat)
      : e_(std::move(entries)), n_(static_cast<int>(n_series)), heat_(std::move(heat)) {}
  Eigen::Index num_residuals() const override { return static_cast<Eigen::Index>(e_.size()); }
  int num_parameters() const override { return 2 * n_ + 1; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    const auto one = [&](Eigen::Index i, const auto* p, auto* out) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      const Entry& e = e_[static_cast<std::size_t>(i)];
      const T y = lag_state<T>(heat_, e.t, thermal_tau<T>(p[2 * n_]));
      out[0] = (p[e.series] + p[n_ + e.series] * y - T(e.value)) / T(e.std);
    };
    evaluate_with_jets(one, num_residuals(), 1, x, r, J);
  }

 private:
  std::vector<Entry> e_;
  int n_;
  HeatInput heat_;
};

}  // namespace

ThermalIdentification fit_lag_to_series(const std::vector<ThermalSeries>& series,
                                        const std::vector<double>& t_mid,
                                        const ThermalTest& thermal, char axis,
                                        const ThermalFitOptions& options) {
  if (options.lags != 1)
    throw InvalidArgument("per-epoch peer: it fits one lag (the method cycle-452 users have)");
  std::vector<SeriesModel::Entry> entries;
  std::vector<FitParameter> cold, gains;
  ThermalFitIndex index;
  const int n = static_cast<int>(series.size());
  for (int k = 0; k < n; ++k) {
    const ThermalSeries& s = series[static_cast<std::size_t>(k)];
    if (s.value.size() != t_mid.size() || s.std.size() != t_mid.size())
      throw InvalidArgument("per-epoch peer: series " + s.name + " has " +
                            std::to_string(s.value.size()) + " epochs for " +
                            std::to_string(t_mid.size()));
    double first = 0.0;
    bool seen = false;
    for (std::size_t e = 0; e < t_mid.size(); ++e)
      if (s.std[e] > 0.0 && std::isfinite(s.value[e])) {
        entries.push_back({k, t_mid[e], s.value[e], s.std[e]});
        if (!seen) first = s.value[e], seen = true;
      }
    // A series no epoch determined is held: nothing in the data moves it.
    cold.push_back({"cold." + s.name, s.unit, first, 0.0, !seen});
    gains.push_back({"K." + s.name, s.unit, 0.0, 0.0, !seen});
    index.cold.push_back(k);
    index.cold_names.push_back(s.name);
    index.gain_names.push_back(s.name);
    index.gain_cold.push_back(k);
  }
  std::vector<FitParameter> params = cold;
  params.insert(params.end(), gains.begin(), gains.end());
  params.push_back({"ln_tau_300s", "1", 0.0});
  index.tau.push_back(2 * n);
  index.gains.push_back(n);
  const SeriesModel model(entries, series.size(), thermal.heat_input(axis));
  JointFitSettings settings;
  settings.max_iterations = options.max_iterations;
  settings.observability_min_chi2 = options.observability_min_chi2;
  settings.sigma = 1.0;  // the residuals are whitened by each epoch's own sigma
  ThermalFitOptions o = options;
  o.noise.noise = NoiseHandling::white;  // one value per epoch: no stream to model
  const bool heated = axis != 0;
  const NoiseFit nf = fit_thermal(model, params, index, heated, settings, {}, {}, o);
  ThermalIdentification out = thermal_identification(nf, index, heated);
  out.axis = axis;
  out.tested_speed_rpm = heated ? thermal.tested_speed(axis) : 0.0;
  out.n_samples = entries.size();
  out.n_epochs = t_mid.size();
  out.residual_rms_um = 0.0;  // whitened residuals: see notes
  out.notes.push_back(
      "per-epoch peer: each epoch identified alone, then one lag fitted to the "
      "series (chi2/dof " +
      std::to_string(nf.fit.summary.chi2_per_dof) + ")");
  out.epoch_series = series;
  out.epoch_mid_s = t_mid;
  return out;
}

}  // namespace rotacal
