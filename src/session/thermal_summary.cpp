// SPDX-License-Identifier: BSD-3-Clause
// The thermal test's answers from its joint fit (session/thermal_summary.hpp).
#include "rotacal/session/thermal_summary.hpp"

#include <algorithm>
#include <cmath>

#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"

namespace rotacal {

namespace {

constexpr double kUpper95 = 1.6448536269514722;  // one-sided 95 % quantile of N(0, 1)

// d(t) and sigma(t) of gain k: (s/100) sum_l K_l g_l(t), g_l = 1 - exp(-t / tau_l) (g_l = 1
// at t = infinity).
struct DriftCurve {
  const ThermalIdentification& id;
  std::size_t k;
  double scale;
  std::pair<double, double> at(double t) const {
    const std::size_t n = id.lags.size();
    std::vector<double> g(n);
    double d = 0.0, var = 0.0;
    for (std::size_t l = 0; l < n; ++l) {
      g[l] = std::isinf(t) ? 1.0 : 1.0 - std::exp(-t / id.lags[l].tau_s);
      d += id.lags[l].gains[k].value * g[l];
    }
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = 0; b < n; ++b)
        var += g[a] * g[b] *
               id.covariance(id.gain_index[a] + static_cast<int>(k),
                             id.gain_index[b] + static_cast<int>(k));
    return {scale * d, scale * std::sqrt(std::max(0.0, var))};
  }
  double bound(double t) const {
    const auto v = at(t);
    return std::abs(v.first) + kUpper95 * v.second;
  }
};

// First t where the curve's upper bound exceeds tol: a scan over 0..20 tau_max (the bound is
// within 2e-9 of its steady state there), then bisection. Unset: never.
std::optional<double> first_exceedance(const DriftCurve& c, double tol, double tau_max) {
  const int n = 4000;
  const double t_end = 20.0 * tau_max;
  double prev = 0.0;
  for (int i = 1; i <= n; ++i) {
    const double t = t_end * i / n;
    if (c.bound(t) > tol) {
      double lo = prev, hi = t;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (c.bound(mid) > tol ? hi : lo) = mid;
      }
      return hi;
    }
    prev = t;
  }
  return std::nullopt;
}

}  // namespace

ThermalDriftTest thermal_drift_test(const ThermalIdentification& id, double level) {
  if (!(level > 0.0 && level < 1.0))
    throw InvalidArgument("thermal drift test: the level must lie in (0, 1), got " +
                          std::to_string(level));
  ThermalDriftTest t;
  t.level = level;
  std::vector<int> idx;
  for (std::size_t l = 0; l < id.lags.size(); ++l)
    for (std::size_t k = 0; k < id.lags[l].gains.size(); ++k)
      if (id.lags[l].gains[k].observable) idx.push_back(id.gain_index[l] + static_cast<int>(k));
  const Eigen::Index p = static_cast<Eigen::Index>(idx.size());
  if (p == 0) return t;
  Eigen::VectorXd g(p), s(p);
  Eigen::MatrixXd c(p, p);
  for (Eigen::Index a = 0; a < p; ++a) {
    g(a) = id.parameters[static_cast<std::size_t>(idx[a])].value;
    for (Eigen::Index b = 0; b < p; ++b) c(a, b) = id.covariance(idx[a], idx[b]);
  }
  // Gains in mm and rad: the correlation matrix R is what gets factored (pivoted LDLT, largest
  // pivots first), and pivots it calls singular (two lags nearly alike) are not tested:
  // W = sum over the kept pivots of y_i^2 / D_i, y = L^-1 P z.
  for (Eigen::Index a = 0; a < p; ++a) s(a) = std::sqrt(std::max(c(a, a), 0.0));
  if ((s.array() <= 0.0).any()) return t;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt((c.array() / (s * s.transpose()).array()).matrix());
  const Eigen::VectorXd d = ldlt.vectorD();
  const Eigen::VectorXd y =
      ldlt.matrixL().solve(ldlt.transpositionsP() * Eigen::VectorXd(g.cwiseQuotient(s)));
  const double tiny = 1e-10 * d.maxCoeff();
  for (Eigen::Index i = 0; i < p; ++i)
    if (d(i) > tiny) {
      t.statistic += y(i) * y(i) / d(i);
      ++t.gains;
    }
  t.residual_dof = id.residual_dof;
  t.p_value = t.residual_dof > 0.0 ? stats::f_sf(t.statistic / t.gains, t.gains, t.residual_dof)
                                   : stats::chi2_sf(t.statistic, t.gains);
  t.drift_found = t.p_value < level;
  return t;
}

ThermalSummary thermal_summary(const ThermalIdentification& id,
                               const ThermalSummaryOptions& options) {
  for (const auto& t : {options.tolerance_mm, options.tolerance_rad})
    if (t && !(std::isfinite(*t) && *t > 0.0))
      throw InvalidArgument("thermal summary: a tolerance must be > 0, got " + std::to_string(*t));
  ThermalSummary s;
  s.axis = id.axis;
  s.tested_speed_rpm = id.tested_speed_rpm;
  double tau_max = 0.0;
  for (const ThermalLag& l : id.lags) {
    s.tau_s.push_back(l.tau_s);
    s.tau_std_s.push_back(l.tau_std_s);
    s.tau_observable.push_back(l.tau_observable);
    tau_max = std::max(tau_max, l.tau_s);
  }
  if (id.lags.empty()) {
    s.no_significant_drift = true;
    return s;
  }
  const double scale = id.tested_speed_rpm / 100.0;
  for (std::size_t k = 0; k < id.lags[0].gains.size(); ++k) {
    const ThermalGainEstimate& g0 = id.lags[0].gains[k];
    ThermalDrift d;
    d.name = g0.name;
    d.unit = g0.unit;
    for (const ThermalLag& l : id.lags)
      if (!l.gains[k].observable) {
        d.observable = false;
        d.reason = l.gains[k].reason;
      }
    d.tolerance = d.unit == "rad" ? options.tolerance_rad : options.tolerance_mm;
    if (!d.observable) {
      s.drifts.push_back(d);
      continue;
    }
    const DriftCurve curve{id, k, scale};
    const auto steady = curve.at(INFINITY);
    d.steady_change = steady.first;
    d.steady_std = steady.second;
    d.significant = std::abs(steady.first) > 3.0 * steady.second;
    if (d.tolerance) d.exceeds_after_s = first_exceedance(curve, *d.tolerance, tau_max);
    s.drifts.push_back(d);
  }
  s.drift_test = thermal_drift_test(id, options.drift_test_level);
  s.no_significant_drift = !s.drift_test.drift_found;
  return s;
}

nlohmann::ordered_json to_json(const ThermalSummary& s) {
  nlohmann::ordered_json j;
  j["axis"] = s.axis ? std::string(1, s.axis) : std::string();
  j["tested_speed_rpm"] = s.tested_speed_rpm;
  j["no_significant_drift"] = s.no_significant_drift;
  const ThermalDriftTest& t = s.drift_test;
  j["drift_test"] = {
      {"statistic", t.statistic}, {"gains", t.gains}, {"residual_dof", t.residual_dof},
      {"p_value", t.p_value},     {"level", t.level}, {"drift_found", t.drift_found}};
  j["lags"] = nlohmann::ordered_json::array();
  for (std::size_t l = 0; l < s.tau_s.size(); ++l)
    j["lags"].push_back({{"tau_s", s.tau_s[l]},
                         {"tau_std_s", s.tau_std_s[l]},
                         {"observable", static_cast<bool>(s.tau_observable[l])}});
  j["drifts"] = nlohmann::ordered_json::array();
  for (const ThermalDrift& d : s.drifts) {
    nlohmann::ordered_json e = {{"name", d.name}, {"unit", d.unit}, {"observable", d.observable}};
    if (!d.observable) {
      e["reason"] = d.reason;
    } else {
      e["steady_change"] = d.steady_change;
      e["steady_std"] = d.steady_std;
      e["significant"] = d.significant;
    }
    if (d.tolerance) {
      e["tolerance"] = *d.tolerance;
      if (d.observable)
        e["exceeds_after_s"] =
            d.exceeds_after_s ? nlohmann::ordered_json(*d.exceeds_after_s) : nullptr;
    }
    j["drifts"].push_back(e);
  }
  return j;
}

namespace {
nlohmann::ordered_json estimate_json(const ThermalGainEstimate& g) {
  nlohmann::ordered_json e = {{"name", g.name}, {"unit", g.unit}, {"observable", g.observable}};
  if (g.observable) {
    e["value"] = g.value;
    e["std"] = g.std;
  } else {
    e["reason"] = g.reason;
  }
  return e;
}
}  // namespace

nlohmann::ordered_json to_json(const ThermalIdentification& id) {
  nlohmann::ordered_json j;
  j["machine"] = to_string(id.machine);
  j["axis"] = id.axis ? std::string(1, id.axis) : std::string();
  j["tested_speed_rpm"] = id.tested_speed_rpm;
  j["converged"] = id.converged;
  j["n_samples"] = id.n_samples;
  j["n_epochs"] = id.n_epochs;
  j["residual_rms_um"] = id.residual_rms_um;
  j["residual_dof"] = id.residual_dof;
  j["noise_model"] = id.noise;
  j["cold"] = nlohmann::ordered_json::array();
  for (const ThermalGainEstimate& c : id.cold) j["cold"].push_back(estimate_json(c));
  j["lags"] = nlohmann::ordered_json::array();
  for (const ThermalLag& l : id.lags) {
    nlohmann::ordered_json lag = {
        {"tau_s", l.tau_s}, {"tau_std_s", l.tau_std_s}, {"tau_observable", l.tau_observable}};
    lag["gains"] = nlohmann::ordered_json::array();
    for (const ThermalGainEstimate& g : l.gains) lag["gains"].push_back(estimate_json(g));
    j["lags"].push_back(lag);
  }
  j["unobservable"] = id.unobservable;
  j["notes"] = id.notes;
  if (!id.epoch_series.empty()) {  // the peer: each epoch's values, what its lag was fitted to
    nlohmann::ordered_json series = nlohmann::ordered_json::array();
    for (const ThermalSeries& s : id.epoch_series) {
      nlohmann::ordered_json value = nlohmann::ordered_json::array(),
                             std = nlohmann::ordered_json::array();
      for (std::size_t e = 0; e < s.value.size(); ++e) {
        const bool known = s.std[e] > 0.0 && std::isfinite(s.value[e]);
        value.push_back(known ? nlohmann::ordered_json(s.value[e]) : nlohmann::ordered_json());
        std.push_back(known ? nlohmann::ordered_json(s.std[e]) : nlohmann::ordered_json());
      }
      series.push_back({{"name", s.name}, {"unit", s.unit}, {"value", value}, {"std", std}});
    }
    j["epochs"] = {{"t_mid_s", id.epoch_mid_s}, {"series", series}};
  }
  return j;
}

}  // namespace rotacal
