// SPDX-License-Identifier: BSD-3-Clause
// The thermal model file, and the location errors it gives at a lag state or a time of a duty
// (io/thermal_model.hpp).
#include "rotacal/io/thermal_model.hpp"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "model_checks.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/controller_export.hpp"
#include "rotacal/kinematics/thermal_lag.hpp"

namespace rotacal {

namespace {

using json = nlohmann::ordered_json;
using model_checks::bad;
using model_checks::estimate;
using model_checks::member;
using model_checks::object_member;
using model_checks::shown;

constexpr double kMaxTauS = 1.0e7;    // s: four months; beyond, not a machine's thermal lag
constexpr double kMaxState = 1000.0;  // u = 1000: 100,000 rev/min

std::string lag_name(std::size_t l) { return "lag" + std::to_string(l + 1); }

json estimate_json(double value, double std, const std::string& unit, bool observable) {
  if (!observable)
    return {{"value", value}, {"std", nullptr}, {"unit", unit}, {"observable", false}};
  return {{"value", value}, {"std", std}, {"unit", unit}};
}

// Parameter names of the model's covariance: 8 cold errors, per lag tau and 8 gains.
std::vector<std::string> covariance_names(MachineType m, std::size_t lags) {
  std::vector<std::string> out(location_error_names(m).begin(), location_error_names(m).end());
  for (std::size_t l = 0; l < lags; ++l) {
    out.push_back(lag_name(l) + ".tau");
    for (const std::string& n : location_error_names(m)) out.push_back(lag_name(l) + "." + n);
  }
  return out;
}

}  // namespace

json thermal_model_document(const ThermalIdentification& id, const HeatInput& test_heat) {
  if (!id.axis || test_heat.start.empty())
    throw InvalidArgument(
        "thermal model: the session has no heat input, nothing drifts to predict");
  const auto& names = location_error_names(id.machine);
  json doc = model_document_header("thermal", id.machine);
  json le = json::object();
  for (std::size_t k = 0; k < 8; ++k)
    le[names[k]] =
        estimate_json(id.cold[k].value, id.cold[k].std, id.cold[k].unit, id.cold[k].observable);
  doc["location_errors"] = le;
  json setup = json::object();  // the instrument's cold set-up (sphere, probe zeros)
  for (std::size_t k = 8; k < id.cold.size(); ++k)
    setup[id.cold[k].name] =
        estimate_json(id.cold[k].value, id.cold[k].std, id.cold[k].unit, id.cold[k].observable);
  json lags = json::array();
  for (const ThermalLag& l : id.lags) {
    json gains = json::object();
    for (const ThermalGainEstimate& g : l.gains)
      gains[g.name] = estimate_json(g.value, g.std, g.unit, g.observable);
    lags.push_back(
        {{"tau", estimate_json(l.tau_s, l.tau_std_s, "s", l.tau_observable)}, {"gains", gains}});
  }
  doc["thermal"] = {{"axis", std::string(1, id.axis)},
                    {"tested_speed_rpm", id.tested_speed_rpm},
                    {"test_heat_input", {{"start_s", test_heat.start}, {"u", test_heat.u}}},
                    {"lags", lags},
                    {"cold_setup", setup}};
  // Covariance in the file's parameters: cold errors by name, tau = 300 s e^q (d tau = tau dq).
  const std::vector<std::string> cn = covariance_names(id.machine, id.lags.size());
  std::vector<int> at;
  std::vector<double> scale;
  std::vector<bool> known;
  for (std::size_t k = 0; k < 8; ++k) {
    int j = -1;
    for (std::size_t p = 0; p < id.parameters.size(); ++p)
      if (id.parameters[p].name == names[k]) j = static_cast<int>(p);
    if (j < 0) throw InvalidArgument("thermal model: the fit has no parameter " + names[k]);
    at.push_back(j), scale.push_back(1.0), known.push_back(id.cold[k].observable);
  }
  for (std::size_t l = 0; l < id.lags.size(); ++l) {
    at.push_back(id.tau_index[l]), scale.push_back(id.lags[l].tau_s);
    known.push_back(id.lags[l].tau_observable);
    for (std::size_t k = 0; k < 8; ++k) {
      at.push_back(id.gain_index[l] + static_cast<int>(k)), scale.push_back(1.0);
      known.push_back(id.lags[l].gains[k].observable);
    }
  }
  json matrix = json::array();
  for (std::size_t a = 0; a < at.size(); ++a) {
    json row = json::array();
    for (std::size_t b = 0; b < at.size(); ++b)
      row.push_back(known[a] && known[b] ? json(scale[a] * scale[b] * id.covariance(at[a], at[b]))
                                         : json(nullptr));
    matrix.push_back(row);
  }
  doc["covariance"] = {{"parameters", cn}, {"matrix", matrix}};
  doc["fit"] = {{"converged", id.converged}, {"residual_rms_um", id.residual_rms_um},
                {"n_samples", id.n_samples}, {"n_epochs", id.n_epochs},
                {"noise_model", id.noise},   {"unobservable", id.unobservable},
                {"notes", id.notes}};
  return doc;
}

void check_thermal_model(const json& doc, MachineType m, const std::string& source) {
  const json& th = object_member(doc, "thermal", source);
  const json& axis = member(th, "axis", source, "thermal");
  const std::string letters{tilt_axis_letter(m), rot_axis_letter(m)};
  if (!axis.is_string() || axis.get<std::string>().size() != 1 ||
      letters.find(axis.get<std::string>()[0]) == std::string::npos)
    bad(source, "thermal.axis", shown(axis) + " is not a rotary axis of " + to_string(m));
  const json& speed = member(th, "tested_speed_rpm", source, "thermal");
  if (!speed.is_number() || !(speed.get<double>() >= 0.0 && speed.get<double>() <= 1e5))
    bad(source, "thermal.tested_speed_rpm", shown(speed) + " is not a speed in [0, 1e5] rev/min");
  const json& heat = object_member(th, "test_heat_input", source, "thermal");
  const json& start = member(heat, "start_s", source, "thermal.test_heat_input");
  const json& u = member(heat, "u", source, "thermal.test_heat_input");
  if (!start.is_array() || !u.is_array() || start.empty() || start.size() != u.size())
    bad(source, "thermal.test_heat_input", "start_s and u must be lists of one length >= 1");
  for (std::size_t i = 0; i < start.size(); ++i) {
    if (!start[i].is_number() || !std::isfinite(start[i].get<double>()) ||
        (i > 0 && !(start[i].get<double>() > start[i - 1].get<double>())))
      bad(source, "thermal.test_heat_input.start_s[" + std::to_string(i) + "]",
          shown(start[i]) + ": the pieces' starts are finite and increasing (s)");
    if (!u[i].is_number() || !(u[i].get<double>() >= 0.0 && u[i].get<double>() <= kMaxState))
      bad(source, "thermal.test_heat_input.u[" + std::to_string(i) + "]",
          shown(u[i]) + " is not a heat input in [0, " + std::to_string(kMaxState) + "]");
  }
  const json& lags = member(th, "lags", source, "thermal");
  if (!lags.is_array() || lags.empty() || lags.size() > 2)
    bad(source, "thermal.lags", "must be a list of 1 or 2 lags");
  const auto& names = location_error_names(m);
  for (std::size_t l = 0; l < lags.size(); ++l) {
    const std::string where = "thermal.lags[" + std::to_string(l) + "]";
    const std::optional<double> tau =
        estimate(member(lags[l], "tau", source, where), where + ".tau", "s", kMaxTauS, source);
    if (tau && !(*tau > 0.0)) bad(source, where + ".tau", "must be > 0 s");
    const json& gains = object_member(lags[l], "gains", source, where);
    for (std::size_t k = 0; k < 8; ++k) {
      const bool angle = location_error_is_angle(static_cast<int>(k));
      estimate(member(gains, names[k], source, where + ".gains"), where + ".gains." + names[k],
               angle ? "rad" : "mm", angle ? kMaxModelAngleError : kMaxModelPositionError, source);
    }
  }
  const json& cov = object_member(doc, "covariance", source);
  const std::vector<std::string> cn = covariance_names(m, lags.size());
  if (member(cov, "parameters", source, "covariance") != json(cn))
    bad(source, "covariance.parameters",
        "must be the 8 location errors, then per lag lagN.tau and lagN.<error> (" +
            std::to_string(cn.size()) + " names)");
  const json& mx = member(cov, "matrix", source, "covariance");
  bool ok = mx.is_array() && mx.size() == cn.size();
  for (std::size_t i = 0; ok && i < mx.size(); ++i) {
    ok = mx[i].is_array() && mx[i].size() == cn.size();
    for (std::size_t j = 0; ok && j < cn.size(); ++j)
      ok = mx[i][j].is_null() || (mx[i][j].is_number() && std::isfinite(mx[i][j].get<double>()));
  }
  if (!ok)
    bad(source, "covariance.matrix",
        "must be " + std::to_string(cn.size()) + " x " + std::to_string(cn.size()) +
            " numbers (null: not determined)");
}

ThermalModel thermal_model(const ModelFile& file, const std::string& source) {
  if (file.kind != "thermal")
    throw InvalidArgument(source + ": a model of kind \"" + file.kind +
                          "\", not a thermal model (rotacal identify THERMAL.csv --save-model)");
  const json& doc = file.document;
  check_thermal_model(doc, file.machine, source);
  ThermalModel m;
  m.machine = file.machine;
  m.cold = file.location_errors;
  m.cold_observable = file.observable;
  const json& th = doc["thermal"];
  m.axis = th["axis"].get<std::string>()[0];
  m.tested_speed_rpm = th["tested_speed_rpm"].get<double>();
  m.test_heat.start = th["test_heat_input"]["start_s"].get<std::vector<double>>();
  m.test_heat.u = th["test_heat_input"]["u"].get<std::vector<double>>();
  const auto& names = location_error_names(m.machine);
  for (const json& l : th["lags"]) {
    ThermalModelLag lag;
    const json& tau = l["tau"];
    if (!tau["value"].is_number() || tau.value("observable", true) == false)
      throw InvalidArgument(source +
                            ": thermal.lags: a tau the test did not determine predicts "
                            "nothing");
    lag.tau_s = tau["value"].get<double>();
    lag.tau_std_s = tau["std"].is_number() ? tau["std"].get<double>() : 0.0;
    for (std::size_t k = 0; k < 8; ++k) {
      const json& g = l["gains"][names[k]];
      lag.gains[static_cast<Eigen::Index>(k)] =
          g["value"].is_number() ? g["value"].get<double>() : 0.0;
      lag.gain_observable[k] = g["value"].is_number() && g.value("observable", true) != false;
    }
    m.lags.push_back(lag);
  }
  const json& mx = doc["covariance"]["matrix"];
  const Eigen::Index n = static_cast<Eigen::Index>(mx.size());
  m.covariance = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const json& x = mx[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      m.covariance(i, j) = x.is_number() ? x.get<double>() : 0.0;
    }
  m.file = file;
  return m;
}

ThermalModel read_thermal_model(const std::string& path) {
  return thermal_model(model_from_json(read_model_document(path), path), path);
}

namespace {

// E = E0 + sum_l K_l y_l with the Jacobian dE/d(cold, tau_l, K_l) (dy_l/dtau_l given).
ThermalErrorsAt errors_at(const ThermalModel& m, const std::vector<double>& y,
                          const std::vector<double>& dy_dtau) {
  ThermalErrorsAt out;
  out.y = y;
  const Eigen::Index n = m.covariance.rows();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(8, n);
  out.errors = m.cold;
  out.observable = m.cold_observable;
  J.leftCols(8).setIdentity();
  for (std::size_t l = 0; l < m.lags.size(); ++l) {
    const ThermalModelLag& lag = m.lags[l];
    ThermalGains<double> k;
    k.errors = lag.gains;
    out.errors = drifted_errors<double>(out.errors, k, y[l]);
    const Eigen::Index c = 8 + 9 * static_cast<Eigen::Index>(l);
    J.col(c) = lag.gains * dy_dtau[l];
    J.block(0, c + 1, 8, 8) = Eigen::Matrix<double, 8, 8>::Identity() * y[l];
    for (std::size_t e = 0; e < 8; ++e)
      out.observable[e] = out.observable[e] && (lag.gain_observable[e] || y[l] == 0.0);
  }
  out.covariance = J * m.covariance * J.transpose();
  return out;
}

}  // namespace

ThermalErrorsAt thermal_errors_at_state(const ThermalModel& m, const std::vector<double>& y) {
  if (y.size() != m.lags.size())
    throw InvalidArgument("thermal state: the model has " + std::to_string(m.lags.size()) +
                          " lag(s), " + std::to_string(y.size()) + " state(s) given");
  for (double v : y)
    if (!(v >= 0.0 && v <= kMaxState))
      throw InvalidArgument("thermal state " + std::to_string(v) +
                            ": a lag state is >= 0 (cold) and at most 1000 (u = |speed| / 100 "
                            "rev/min)");
  return errors_at(m, y, std::vector<double>(y.size(), 0.0));
}

ThermalErrorsAt thermal_errors_at_time(const ThermalModel& m, const HeatInput& heat, double t) {
  if (!std::isfinite(t)) throw InvalidArgument("thermal prediction: a time must be finite");
  using Jet = ceres::Jet<double, 1>;
  std::vector<double> y, dy;
  for (const ThermalModelLag& lag : m.lags) {
    const Jet s = lag_state<Jet>(heat, t, Jet(lag.tau_s, 0));
    y.push_back(s.a), dy.push_back(s.v[0]);
  }
  return errors_at(m, y, dy);
}

std::vector<double> thermal_prediction_times(const ThermalModel& m, const HeatInput& heat,
                                             double step_s) {
  if (heat.start.empty()) return {};
  double tau = 0.0;
  for (const ThermalModelLag& l : m.lags) tau = std::max(tau, l.tau_s);
  const double t0 = heat.start.front(), t1 = heat.start.back() + 5.0 * tau;
  if (!(step_s > 0.0) || (t1 - t0) / step_s > 1.0e6)
    throw InvalidArgument("thermal prediction: a step of " + std::to_string(step_s) +
                          " s gives more than 1e6 times");
  std::vector<double> out;
  for (long i = 0; t0 + static_cast<double>(i) * step_s <= t1 + 1e-9; ++i)
    out.push_back(t0 + static_cast<double>(i) * step_s);
  return out;
}

ExportInput thermal_export_input(const ThermalModel& m, const ThermalErrorsAt& at,
                                 const std::string& model_path, const std::string& state) {
  // The file with its errors and covariance replaced by the state's: export_input reads the
  // rest (source) as for any model.
  ModelFile f = m.file;
  f.kind = "thermal-state";
  f.location_errors = at.errors;
  f.observable = at.observable;
  const auto& names = location_error_names(m.machine);
  json cov = json::array();
  for (std::size_t i = 0; i < 8; ++i) {
    json& e = f.document["location_errors"][names[i]];
    e["value"] = at.errors.v[static_cast<Eigen::Index>(i)];
    e["std"] = at.observable[i] ? json(std::sqrt(at.covariance(i, i))) : json(nullptr);
    json row = json::array();
    for (std::size_t j = 0; j < 8; ++j) row.push_back(at.covariance(i, j));
    cov.push_back(row);
  }
  f.document["covariance"] = {{"parameters", names}, {"matrix", cov}};
  ExportInput in = export_input(f, model_path);
  in.source += (in.source.empty() ? "" : "; ") + std::string("thermal state ") + state;
  return in;
}

}  // namespace rotacal
