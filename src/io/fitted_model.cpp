// SPDX-License-Identifier: BSD-3-Clause
// The "probe" and "multi" kinds of rotacal-model/1 files, written and read back strictly
// (io/fitted_model.hpp; the layout in docs/model_file.md).
#include "rotacal/io/fitted_model.hpp"

#include <cmath>
#include <limits>
#include <set>

#include "model_checks.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"

namespace rotacal {

namespace {

using json = nlohmann::ordered_json;
using model_checks::bad;
using model_checks::member;
using model_checks::object_member;
using model_checks::shown;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ----------------------------------------------------------------- writing

json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

// {"value", "std", "unit"}; an unobservable parameter has neither value nor std.
json estimate_json(const ParameterEstimate& p) {
  if (!p.observable)
    return {{"value", nullptr}, {"std", nullptr}, {"unit", p.unit}, {"observable", false}};
  return {{"value", number_or_null(p.value)}, {"std", number_or_null(p.std)}, {"unit", p.unit}};
}

json estimates_json(const std::vector<ParameterEstimate>& ps) {
  json out = json::object();
  for (const ParameterEstimate& p : ps) out[p.name] = estimate_json(p);
  return out;
}

// The noise model as docs/json_schema.md#noise-model has it (rotacal.results.noise_model_dict).
json noise_json(const NoiseModel& nm, bool refit, double correction) {
  json streams = json::array();
  for (const NoiseStream& s : nm.streams)
    streams.push_back({{"group", s.group},
                       {"channel", s.channel},
                       {"order", s.order()},
                       {"ar", s.ar},
                       {"sigma_um", s.marginal_sigma_um},
                       {"innovation_sigma_um", s.innovation_sigma_um},
                       {"correlation_samples", s.correlation_samples},
                       {"sample_interval_s", s.sample_interval_s},
                       {"correlation_time_s", s.correlation_time_s},
                       {"effective_samples", s.effective_samples},
                       {"random_walk_step_um", s.random_walk_step_um}});
  return {{"white", nm.white()},
          {"summary", nm.summary()},
          {"n", nm.n},
          {"sigma_um", nm.sigma_um},
          {"innovation_sigma_um", nm.innovation_sigma_um},
          {"max_order", nm.max_order},
          {"random_walk_step_um", nm.random_walk_step_um},
          {"correlation_samples", nm.correlation_samples},
          {"correlation_time_s", nm.correlation_time_s},
          {"effective_samples", nm.effective_samples},
          {"streams", streams},
          {"gls_refit", refit},
          {"covariance_factor", correction}};
}

json effects_json(const FittedModelContent& c) {
  json fx = json::array();
  std::size_t at = 0;
  for (const Effect& e : c.effects.effects) {
    json params = json::object();
    const auto pn = e.param_names();
    for (std::size_t k = 0; k < pn.size(); ++k)
      params[pn[k]] = estimate_json(c.effect_parameters[at++]);
    fx.push_back({{"id", e.id()}, {"cause", e.cause()}, {"params", params}});
  }
  return fx;
}

json sessions_json(const FittedModelContent& c) {
  json out = json::array();
  for (const FittedSessionContent& s : c.sessions) {
    json one = {
        {"name", s.name}, {"instrument", s.instrument}, {"nuisances", estimates_json(s.nuisances)}};
    if (c.kind == "multi") one["alone"] = estimates_json(s.alone);
    one["noise_model"] = noise_json(s.noise, s.noise_refit, s.noise_correction);
    one["residual_rms_um"] = s.residual_rms_um;
    one["n_residuals"] = s.n_residuals;
    out.push_back(one);
  }
  return out;
}

void check_content(const FittedModelContent& c) {
  const std::string w = "fitted_model_document: ";
  if (c.kind != "probe" && c.kind != "multi")
    throw InvalidArgument(w + "kind '" + c.kind + "' is not probe or multi");
  if (c.location_errors.size() != 8)
    throw InvalidArgument(w + std::to_string(c.location_errors.size()) + " location errors, not 8");
  if (c.effect_parameters.size() != static_cast<std::size_t>(c.effects.num_params()))
    throw InvalidArgument(w + "effect_parameters has " +
                          std::to_string(c.effect_parameters.size()) + " values, the effects " +
                          std::to_string(c.effects.num_params()));
  const auto n = static_cast<Eigen::Index>(c.covariance_parameters.size());
  if (c.covariance.rows() != n || c.covariance.cols() != n)
    throw InvalidArgument(w + "the covariance is not " + std::to_string(n) + " x " +
                          std::to_string(n));
  if (c.kind == "probe" && c.sessions.size() != 1)
    throw InvalidArgument(w + "a probe model holds one session, not " +
                          std::to_string(c.sessions.size()));
}

// ----------------------------------------------------------------- reading

struct FittedModelReader {
  const std::string& source;

  // An estimate of `unit` within `limit`; value null or "observable": false -> unobservable.
  ParameterEstimate estimate(const json& e, const std::string& name, const std::string& where,
                             const std::string& unit, double limit) const {
    ParameterEstimate p{name, 0.0, kNaN, unit, true};
    const std::optional<double> v = model_checks::estimate(e, where, unit, limit, source);
    if (e.contains("observable") && !e["observable"].is_boolean())
      bad(source, where + ".observable", "must be true or false, got " + shown(e["observable"]));
    p.observable = v.has_value() && e.value("observable", true);
    if (p.observable) p.value = *v;
    if (e.contains("std") && e["std"].is_number()) p.std = e["std"].get<double>();
    return p;
  }

  // A session's own parameter (a sphere or pivot position, a probe zero, a tool offset): mm
  // within the pivot limit or rad within the angle limit, as the file says.
  ParameterEstimate own_estimate(const json& e, const std::string& name,
                                 const std::string& where) const {
    if (!e.is_object() || !e.contains("unit") || !e["unit"].is_string())
      bad(source, where,
          "must be an estimate {\"value\", \"std\", \"unit\"} with its unit, got " + shown(e));
    const std::string unit = e["unit"].get<std::string>();
    if (unit != "mm" && unit != "rad")
      bad(source, where + ".unit", shown(e["unit"]) + ": must be mm or rad");
    return estimate(e, name, where, unit, unit == "mm" ? kMaxModelPivot : kMaxModelAngleError);
  }

  std::vector<ParameterEstimate> location_errors(const json& le, MachineType m,
                                                 const std::string& where) const {
    std::vector<ParameterEstimate> out;
    const auto& names = location_error_names(m);
    for (int k = 0; k < 8; ++k) {
      const bool angle = location_error_is_angle(k);
      const std::string& n = names[static_cast<std::size_t>(k)];
      out.push_back(estimate(member(le, n, source, where), n, where + "." + n, angle ? "rad" : "mm",
                             angle ? kMaxModelAngleError : kMaxModelPositionError));
    }
    for (auto it = le.begin(); it != le.end(); ++it)
      if (std::find(names.begin(), names.end(), it.key()) == names.end())
        bad(source, where + "." + it.key(),
            "is not a location error of a " + to_string(m) + " machine");
    return out;
  }

  double number(const json& obj, const std::string& key, const std::string& where,
                double lo) const {
    const json& v = member(obj, key, source, where);
    if (!v.is_number() || !(v.get<double>() >= lo) || !std::isfinite(v.get<double>()))
      bad(source, where + "." + key,
          "must be a finite number >= " + json(lo).dump() + ", got " + shown(v));
    return v.get<double>();
  }

  bool boolean(const json& obj, const std::string& key, const std::string& where) const {
    const json& v = member(obj, key, source, where);
    if (!v.is_boolean()) bad(source, where + "." + key, "must be true or false, got " + shown(v));
    return v.get<bool>();
  }

  std::string text(const json& obj, const std::string& key, const std::string& where) const {
    const json& v = member(obj, key, source, where);
    if (!v.is_string()) bad(source, where + "." + key, "must be a string, got " + shown(v));
    return v.get<std::string>();
  }

  std::vector<std::string> texts(const json& obj, const std::string& key,
                                 const std::string& where) const {
    const json& v = member(obj, key, source, where);
    if (!v.is_array()) bad(source, where + "." + key, "must be a list of strings, got " + shown(v));
    std::vector<std::string> out;
    for (const json& x : v) {
      if (!x.is_string())
        bad(source, where + "." + key, "must be a list of strings, got " + shown(x));
      out.push_back(x.get<std::string>());
    }
    return out;
  }

  NoiseModel noise(const json& nm, const std::string& where, bool& refit,
                   double& correction) const {
    if (!nm.is_object()) bad(source, where, "must be a noise model object, got " + shown(nm));
    NoiseModel out;
    out.n = static_cast<std::size_t>(number(nm, "n", where, 0.0));
    out.sigma_um = number(nm, "sigma_um", where, 0.0);
    out.innovation_sigma_um = number(nm, "innovation_sigma_um", where, 0.0);
    out.max_order = static_cast<int>(number(nm, "max_order", where, 0.0));
    out.random_walk_step_um = number(nm, "random_walk_step_um", where, 0.0);
    out.correlation_samples = number(nm, "correlation_samples", where, 0.0);
    out.correlation_time_s = number(nm, "correlation_time_s", where, 0.0);
    out.effective_samples = number(nm, "effective_samples", where, 0.0);
    refit = boolean(nm, "gls_refit", where);
    correction = number(nm, "covariance_factor", where, 0.0);
    const json& streams = member(nm, "streams", source, where);
    if (!streams.is_array())
      bad(source, where + ".streams", "must be a list, got " + shown(streams));
    for (std::size_t i = 0; i < streams.size(); ++i) {
      const std::string at = where + ".streams[" + std::to_string(i) + "]";
      const json& s = streams[i];
      if (!s.is_object()) bad(source, at, "must be an object, got " + shown(s));
      NoiseStream st;
      st.group = text(s, "group", at);
      st.channel = static_cast<int>(number(s, "channel", at, 0.0));
      const json& ar = member(s, "ar", source, at);
      if (!ar.is_array()) bad(source, at + ".ar", "must be a list of numbers, got " + shown(ar));
      for (const json& x : ar) {
        if (!x.is_number() || !std::isfinite(x.get<double>()))
          bad(source, at + ".ar", "must be a list of finite numbers, got " + shown(x));
        st.ar.push_back(x.get<double>());
      }
      if (number(s, "order", at, 0.0) != static_cast<double>(st.ar.size()))
        bad(source, at + ".order",
            shown(s["order"]) + " is not the number of AR coefficients (" +
                std::to_string(st.ar.size()) + ")");
      st.marginal_sigma_um = number(s, "sigma_um", at, 0.0);
      st.innovation_sigma_um = number(s, "innovation_sigma_um", at, 0.0);
      st.correlation_samples = number(s, "correlation_samples", at, 0.0);
      st.sample_interval_s = number(s, "sample_interval_s", at, 0.0);
      st.correlation_time_s = number(s, "correlation_time_s", at, 0.0);
      st.effective_samples = number(s, "effective_samples", at, 0.0);
      st.random_walk_step_um = number(s, "random_walk_step_um", at, 0.0);
      out.streams.push_back(std::move(st));
    }
    const bool white = boolean(nm, "white", where);
    if (white != out.white())
      bad(source, where + ".white",
          shown(nm["white"]) + " contradicts max_order and random_walk_step_um");
    return out;
  }

  FittedSessionContent session(const json& s, const std::string& where, MachineType m,
                               const std::string& kind,
                               const std::vector<ParameterEstimate>& shared) const {
    if (!s.is_object()) bad(source, where, "must be an object, got " + shown(s));
    FittedSessionContent out;
    out.name = text(s, "name", where);
    out.instrument = text(s, "instrument", where);
    if (out.instrument != "ballbar" && out.instrument != "rtest" && out.instrument != "probe")
      bad(source, where + ".instrument",
          shown(s["instrument"]) + " is not ballbar, rtest or probe");
    if (kind == "probe" && out.instrument != "probe")
      bad(source, where + ".instrument",
          "a probe model's session is a touch-probe session, not " + out.instrument);
    const json& own = object_member(s, "nuisances", source, where);
    for (auto it = own.begin(); it != own.end(); ++it)
      out.nuisances.push_back(own_estimate(it.value(), it.key(), where + ".nuisances." + it.key()));
    if (kind == "multi") {
      const json& alone = object_member(s, "alone", source, where);
      out.alone = location_errors_and(alone, m, shared, where + ".alone");
    }
    out.noise = noise(member(s, "noise_model", source, where), where + ".noise_model",
                      out.noise_refit, out.noise_correction);
    out.residual_rms_um = number(s, "residual_rms_um", where, 0.0);
    out.n_residuals = static_cast<std::size_t>(number(s, "n_residuals", where, 0.0));
    return out;
  }

  // The location errors, then the shared effect parameters (named as in `shared`, their units).
  std::vector<ParameterEstimate> location_errors_and(const json& obj, MachineType m,
                                                     const std::vector<ParameterEstimate>& shared,
                                                     const std::string& where) const {
    json le = json::object();
    for (auto it = obj.begin(); it != obj.end(); ++it)
      if (std::none_of(shared.begin(), shared.end(),
                       [&](const ParameterEstimate& p) { return p.name == it.key(); }))
        le[it.key()] = it.value();
    std::vector<ParameterEstimate> out = location_errors(le, m, where);
    for (const ParameterEstimate& p : shared)
      out.push_back(estimate(member(obj, p.name, source, where), p.name, where + "." + p.name,
                             p.unit, 1.0e6));
    return out;
  }

  FittedDisagreement disagreement(const json& d, const std::string& where) const {
    if (!d.is_object()) bad(source, where, "must be an object, got " + shown(d));
    FittedDisagreement out;
    out.parameter = text(d, "parameter", where);
    out.unit = text(d, "unit", where);
    const std::vector<std::string> s = texts(d, "sessions", where);
    if (s.size() != 2) bad(source, where + ".sessions", "must name two sessions");
    out.session_a = s[0];
    out.session_b = s[1];
    const json& v = member(d, "values", source, where);
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      bad(source, where + ".values", "must be two numbers, got " + shown(v));
    out.value_a = v[0].get<double>();
    out.value_b = v[1].get<double>();
    out.difference = number(d, "difference", where, -std::numeric_limits<double>::infinity());
    out.sigma = number(d, "sigma", where, 0.0);
    out.z = number(d, "z", where, -std::numeric_limits<double>::infinity());
    return out;
  }

  void covariance(const json& doc, FittedModelContent& c) const {
    const json& cov = object_member(doc, "covariance", source);
    c.covariance_parameters = texts(cov, "parameters", "covariance");
    std::set<std::string> expected,
        given(c.covariance_parameters.begin(), c.covariance_parameters.end());
    for (const ParameterEstimate& p : c.location_errors) expected.insert(p.name);
    for (const ParameterEstimate& p : c.effect_parameters) expected.insert(p.name);
    for (const FittedSessionContent& s : c.sessions)
      for (const ParameterEstimate& p : s.nuisances)
        expected.insert(c.kind == "multi" ? s.name + ":" + p.name : p.name);
    if (given.size() != c.covariance_parameters.size() || given != expected)
      bad(source, "covariance.parameters",
          "must list each of the " + std::to_string(expected.size()) +
              " fitted parameters once (location errors, "
              "effect parameters, the sessions' own parameters" +
              (c.kind == "multi" ? " as <session>:<name>" : "") + ")");
    const std::size_t n = c.covariance_parameters.size();
    const json& m = member(cov, "matrix", source, "covariance");
    if (!m.is_array() || m.size() != n)
      bad(source, "covariance.matrix", "must be " + std::to_string(n) + " rows");
    c.covariance.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    for (std::size_t i = 0; i < n; ++i) {
      const std::string at = "covariance.matrix[" + std::to_string(i) + "]";
      if (!m[i].is_array() || m[i].size() != n)
        bad(source, at, "must be " + std::to_string(n) + " numbers");
      for (std::size_t j = 0; j < n; ++j) {
        const json& x = m[i][j];
        if (!x.is_number() && !x.is_null())
          bad(source, at, "must hold numbers (or null), got " + shown(x));
        c.covariance(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            x.is_null() ? kNaN : x.get<double>();
      }
    }
  }
};

// The names of the covariance's parameters that the fit could not determine: their rows are null.
std::set<std::string> undetermined(const FittedModelContent& c) {
  std::set<std::string> out;
  for (const auto* ps : {&c.location_errors, &c.effect_parameters})
    for (const ParameterEstimate& p : *ps)
      if (!p.observable) out.insert(p.name);
  for (const FittedSessionContent& s : c.sessions)
    for (const ParameterEstimate& p : s.nuisances)
      if (!p.observable) out.insert(c.kind == "multi" ? s.name + ":" + p.name : p.name);
  return out;
}

}  // namespace

json fitted_model_document(const FittedModelContent& c) {
  check_content(c);
  const std::set<std::string> unknown = undetermined(c);
  json doc = model_document_header(c.kind, c.machine);
  doc["model"] = c.effects.effects.empty() ? "baseline" : "extended";
  doc["location_errors"] = estimates_json(c.location_errors);
  doc["effects"] = effects_json(c);
  json names = json::array(), matrix = json::array();
  for (std::size_t i = 0; i < c.covariance_parameters.size(); ++i) {
    names.push_back(c.covariance_parameters[i]);
    json row = json::array();
    for (std::size_t j = 0; j < c.covariance_parameters.size(); ++j)
      row.push_back(unknown.count(c.covariance_parameters[i]) ||
                            unknown.count(c.covariance_parameters[j])
                        ? json(nullptr)
                        : number_or_null(c.covariance(static_cast<Eigen::Index>(i),
                                                      static_cast<Eigen::Index>(j))));
    matrix.push_back(row);
  }
  doc["covariance"] = {{"parameters", names}, {"matrix", matrix}};
  doc["sessions"] = sessions_json(c);
  if (c.kind == "multi") {
    json ds = json::array();
    for (const FittedDisagreement& d : c.disagreements)
      ds.push_back({{"parameter", d.parameter},
                    {"unit", d.unit},
                    {"sessions", {d.session_a, d.session_b}},
                    {"values", {d.value_a, d.value_b}},
                    {"difference", d.difference},
                    {"sigma", d.sigma},
                    {"z", d.z}});
    doc["disagreements"] = ds;
  }
  doc["fit"] = {{"converged", c.converged},
                {"chi2_per_dof", number_or_null(c.chi2_per_dof)},
                {"unobservable", c.unobservable},
                {"notes", c.notes}};
  if (c.kind == "multi") doc["fit"]["sigma_inflated"] = c.sigma_inflated;
  return doc;
}

FittedModelContent fitted_model_from_json(const json& doc, MachineType machine,
                                          const std::string& source) {
  const FittedModelReader r{source};
  FittedModelContent c;
  c.kind = r.text(doc, "kind", "");
  if (c.kind != "probe" && c.kind != "multi")
    bad(source, "kind", shown(doc["kind"]) + " is not probe or multi");
  c.machine = machine;
  c.location_errors =
      r.location_errors(object_member(doc, "location_errors", source), machine, "location_errors");
  const json& fx = member(doc, "effects", source, "");
  if (!fx.is_array()) bad(source, "effects", "must be a list, got " + shown(fx));
  for (std::size_t i = 0; i < fx.size(); ++i) {  // ids and units were checked by model_from_json
    const std::string where = "effects[" + std::to_string(i) + "]";
    const Effect e = Effect::parse(r.text(fx[i], "id", where));
    const json& params = object_member(fx[i], "params", source, where);
    const auto pn = e.param_names(), pu = e.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      c.effect_parameters.push_back(r.estimate(member(params, pn[k], source, where + ".params"),
                                               effect_parameter_name(e, k),
                                               where + ".params." + pn[k], pu[k], 1.0e6));
    c.effects.effects.push_back(e);
  }
  const std::string model = r.text(doc, "model", "");
  if (model != (c.effects.effects.empty() ? "baseline" : "extended"))
    bad(source, "model",
        shown(doc["model"]) +
            (c.effects.effects.empty()
                 ? ": no effects were fitted along, so the values are the baseline's"
                 : ": effects were fitted along, so the values are the extended model's"));
  const json& sessions = member(doc, "sessions", source, "");
  if (!sessions.is_array() || sessions.empty())
    bad(source, "sessions", "must be a non-empty list, got " + shown(sessions));
  if (c.kind == "probe" && sessions.size() != 1)
    bad(source, "sessions", "a probe model holds exactly one session");
  if (c.kind == "multi" && sessions.size() < 2)
    bad(source, "sessions", "a multi model holds two sessions or more");
  std::set<std::string> names;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    c.sessions.push_back(r.session(sessions[i], "sessions[" + std::to_string(i) + "]", machine,
                                   c.kind, c.effect_parameters));
    if (!names.insert(c.sessions.back().name).second)
      bad(source, "sessions[" + std::to_string(i) + "].name",
          shown(c.sessions.back().name) + " is named twice");
  }
  if (c.kind == "multi") {
    const json& ds = member(doc, "disagreements", source, "");
    if (!ds.is_array()) bad(source, "disagreements", "must be a list, got " + shown(ds));
    for (std::size_t i = 0; i < ds.size(); ++i)
      c.disagreements.push_back(r.disagreement(ds[i], "disagreements[" + std::to_string(i) + "]"));
  }
  r.covariance(doc, c);
  const json& fit = object_member(doc, "fit", source);
  c.converged = r.boolean(fit, "converged", "fit");
  const json& chi = member(fit, "chi2_per_dof", source, "fit");
  c.chi2_per_dof = chi.is_null() ? kNaN : r.number(fit, "chi2_per_dof", "fit", 0.0);
  c.unobservable = r.texts(fit, "unobservable", "fit");
  c.notes = r.texts(fit, "notes", "fit");
  if (fit.contains("sigma_inflated")) c.sigma_inflated = r.boolean(fit, "sigma_inflated", "fit");
  return c;
}

FittedModelContent fitted_model_content(const ModelFile& model, const std::string& source) {
  if (model.kind != "probe" && model.kind != "multi")
    bad(source, "kind", "a " + model.kind + " model is not a probe or multi model");
  return fitted_model_from_json(model.document, model.machine, source);
}

}  // namespace rotacal
