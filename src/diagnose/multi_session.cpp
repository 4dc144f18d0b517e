// SPDX-License-Identifier: BSD-3-Clause
// One diagnosis of several sessions of one machine (diagnose/multi_session.hpp): the sessions'
// problems stacked as one problem of the engine, the joint fit one GLS step from their own.
#include "rotacal/diagnose/multi_session.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <set>

#include "rotacal/diagnose/ballbar_diagnosis.hpp"
#include "rotacal/diagnose/probe_diagnosis.hpp"
#include "rotacal/diagnose/rtest_diagnosis.hpp"
#include "rotacal/probe/problem.hpp"

namespace rotacal {

DiagnosisSession DiagnosisSession::of(std::string name, BallbarSession session) {
  return {std::move(name), std::make_shared<const BallbarDiagnosisProblem>(std::move(session)),
          nullptr};
}
DiagnosisSession DiagnosisSession::of(std::string name, RtestSession session) {
  return {std::move(name), std::make_shared<const RtestDiagnosisProblem>(std::move(session)),
          nullptr};
}
DiagnosisSession DiagnosisSession::of(std::string name, ProbeSession session) {
  auto touches = std::make_shared<const ProbeSession>(std::move(session));
  return {std::move(name), std::make_shared<const ProbeDiagnosisProblem>(*touches), touches};
}

bool is_machine_effect(const Effect& e) {
  switch (e.kind) {
    case EffectKind::ballbar_length_offset:  // the instrument's
    case EffectKind::ballbar_thermal_drift:
    case EffectKind::stylus_radius_offset:
    case EffectKind::probe_lobing:
    case EffectKind::tool_offset_Z:  // the set-up's
    case EffectKind::tool_offset:
    case EffectKind::thermal_drift:  // the session's clock: t counts from its own start
    case EffectKind::thermal_warmup:
      return false;
    default:
      return true;
  }
}

namespace {

std::string model_key(const EffectModel& m) {
  std::string k;
  for (const Effect& e : m.effects) k += e.id() + ";";
  return k;
}

bool is_parameter_of(const std::string& name, const std::string& id) {
  return name == id || name.rfind(id + ".", 0) == 0;
}

void check_sessions(const std::vector<DiagnosisSession>& sessions) {
  if (sessions.empty()) throw InvalidArgument("diagnose: no session to diagnose");
  std::set<std::string> names;
  for (const DiagnosisSession& s : sessions) {
    if (!s.problem) throw InvalidArgument("diagnose: session " + s.name + " holds no data");
    if (s.name.empty() || s.name.find(':') != std::string::npos)
      throw InvalidArgument("diagnose: session name '" + s.name +
                            "' must be non-empty and without ':' (it prefixes its effects' ids)");
    if (!names.insert(s.name).second)
      throw InvalidArgument("diagnose: session name " + s.name + " given twice");
  }
  const DiagnosisSession& first = sessions.front();
  const MachineType m = first.problem->machine();
  for (const DiagnosisSession& s : sessions) {
    const MachineType ms = s.problem->machine();
    if (ms != m && to_string(ms) == to_string(m))
      throw InvalidArgument("diagnose: sessions " + first.name + " and " + s.name +
                            " name one machine, " + to_string(m) +
                            ", with two different descriptions (axes or lengths differ): a "
                            "diagnosis of several sessions is of one machine; give both its one "
                            "description");
    if (ms != m)
      throw InvalidArgument("diagnose: sessions of different machine types: " + first.name +
                            " is " + to_string(m) + ", " + s.name + " is " + to_string(ms) +
                            "; a diagnosis of several sessions is of one machine");
  }
}

bool same_sphere(const ProbeSession& a, const ProbeSession& b) {
  return (a.sphere - b.sphere).norm() < 1e-6 &&
         std::abs(a.sphere_diameter - b.sphere_diameter) < 1e-9 &&
         std::abs(a.stylus_diameter - b.stylus_diameter) < 1e-9;
}

// A touch-probe session with no more touches than its own unknowns (location errors, sphere:
// the one pose `design probe --after S` may propose) cannot be fitted alone, and with a sphere
// of its own it would tell nothing. The design counted on the sphere staying on the table, so
// its touches join the last earlier probe session of the same sphere as its continuation: times
// after that session's (one mean touch spacing on), pose labels prefixed where they repeat.
std::vector<std::string> join_continuations(std::vector<DiagnosisSession>& sessions) {
  std::vector<std::string> notes;
  for (std::size_t k = 0; k < sessions.size();) {
    const std::shared_ptr<const ProbeSession> added = sessions[k].probe;
    if (!added || added->samples.empty()) {
      ++k;
      continue;
    }
    const ProbeProblem alone(*added);
    if (alone.num_residuals() > alone.num_parameters()) {
      ++k;
      continue;
    }
    std::size_t j = k;
    for (std::size_t i = 0; i < k; ++i)
      if (sessions[i].probe && same_sphere(*sessions[i].probe, *added)) j = i;
    const std::string counts = std::to_string(alone.num_residuals()) + " touches for " +
                               std::to_string(alone.num_parameters()) + " unknowns";
    if (j == k)
      throw InvalidArgument(
          "diagnose: session " + sessions[k].name + " cannot be fitted alone (" + counts +
          ") and no earlier touch-probe session of the same sphere (nominal centre and "
          "diameters) precedes it to continue; give the session it was designed after first");
    ProbeSession joined = *sessions[j].probe;
    const std::vector<std::string> labels = joined.poses();
    const double first = joined.samples.front().time, last = joined.samples.back().time;
    const double spacing =
        joined.samples.size() > 1 ? (last - first) / double(joined.samples.size() - 1) : 1.0;
    const double shift = std::max(0.0, last + spacing - added->samples.front().time);
    for (ProbeSample t : added->samples) {
      if (std::find(labels.begin(), labels.end(), t.pose) != labels.end())
        t.pose = sessions[k].name + ":" + t.pose;
      t.time += shift;
      joined.samples.push_back(std::move(t));
    }
    notes.push_back("session " + sessions[k].name + " is not fitted alone (" + counts +
                    "): its touches are diagnosed as a continuation of session " +
                    sessions[j].name +
                    " (the sphere not moved between them, as `rotacal design probe --after` "
                    "assumes), its times shifted by " +
                    std::to_string(static_cast<long long>(std::lround(shift))) + " s");
    sessions[j] = DiagnosisSession::of(sessions[j].name, std::move(joined));
    sessions.erase(sessions.begin() + static_cast<std::ptrdiff_t>(k));
  }
  return notes;
}

}  // namespace

MultiDiagnosisProblem::MultiDiagnosisProblem(std::vector<DiagnosisSession> sessions)
    : sessions_(std::move(sessions)) {
  check_sessions(sessions_);
  machine_ = sessions_.front().problem->machine();
  fits_.resize(sessions_.size());
  models_.resize(sessions_.size());
  offsets_.push_back(0);
  bool all_declared = true;
  for (std::size_t k = 0; k < sessions_.size(); ++k) {
    const DiagnosisProblem& P = *sessions_[k].problem;
    for (const std::string& g : P.groups()) groups_.push_back(sessions_[k].name + ":" + g);
    times_.insert(times_.end(), P.times().begin(), P.times().end());
    angles_.insert(angles_.end(), P.angles().begin(), P.angles().end());
    const Eigen::Index n = static_cast<Eigen::Index>(P.groups().size());
    offsets_.push_back(offsets_.back() + n);
    mean_xyz_ += static_cast<double>(n) * P.mean_commanded_xyz();
    correlation_bound_z_ = std::max(correlation_bound_z_, P.correlation_bound_z());
    double noise = P.declared_noise_um().value_or(0.0);
    if (!P.declared_noise_um()) {
      all_declared = false;
      noise = estimate_noise_um(P, session_fit(k, EffectModel{}).residuals);
    }
    if (!(noise > 0.0))
      throw InvalidArgument("diagnose: session " + sessions_[k].name +
                            " has no noise to weigh its readings by (declared or estimated: " +
                            std::to_string(noise) + " um)");
    noise_um_.push_back(noise);
  }
  mean_xyz_ /= static_cast<double>(offsets_.back());
  for (double s : noise_um_) weights_.push_back(noise_um_.front() / s);
  if (all_declared) declared_ = noise_um_.front();
}

bool MultiDiagnosisProblem::models(std::size_t k, const Effect& e) const {
  const std::string id = e.id();
  auto it = models_[k].find(id);
  if (it == models_[k].end()) {
    const std::vector<Effect> c = sessions_[k].problem->candidates(std::max(1, e.harmonic));
    it = models_[k].emplace(id, std::find(c.begin(), c.end(), e) != c.end()).first;
  }
  return it->second;
}

std::vector<Effect> MultiDiagnosisProblem::candidates(int max_harmonic) const {
  std::vector<Effect> machine, own;
  for (const DiagnosisSession& s : sessions_)
    for (Effect e : s.problem->candidates(max_harmonic)) {
      if (is_machine_effect(e)) {
        if (std::find(machine.begin(), machine.end(), e) == machine.end()) machine.push_back(e);
      } else {
        e.session = s.name;
        own.push_back(e);
      }
    }
  machine.insert(machine.end(), own.begin(), own.end());
  return machine;
}

EffectModel MultiDiagnosisProblem::share(std::size_t k, const EffectModel& joint) const {
  EffectModel out;
  out.linear_reference = joint.linear_reference;
  for (const Effect& e : joint.effects) {
    if (e.session.empty()) {
      if (models(k, e)) out.effects.push_back(e);
    } else if (e.session == sessions_[k].name) {
      Effect own = e;
      own.session.clear();
      out.effects.push_back(own);
    }
  }
  return out;
}

const ModelFit& MultiDiagnosisProblem::session_fit(std::size_t k, const EffectModel& share) const {
  const std::string key = model_key(share);
  auto it = fits_[k].find(key);
  if (it == fits_[k].end()) {
    ModelFit f = sessions_[k].problem->fit(share);
    if (f.residuals.size() != static_cast<Eigen::Index>(sessions_[k].problem->groups().size()))
      throw InvalidArgument("diagnose: session " + sessions_[k].name + ": its fit gives " +
                            std::to_string(f.residuals.size()) + " residuals for " +
                            std::to_string(sessions_[k].problem->groups().size()) + " readings");
    for (std::size_t i = 0; i < f.held.size(); ++i)  // held alone, another session may tell
      f.jacobian.col(f.held[i]) = f.held_columns.col(static_cast<Eigen::Index>(i));
    it = fits_[k].emplace(key, std::move(f)).first;
  }
  return it->second;
}

std::vector<std::string> MultiDiagnosisProblem::joint_names(std::size_t k, const EffectModel& share,
                                                            const ModelFit& f) const {
  const auto& errors = location_error_names(machine_);
  const std::string prefix = sessions_[k].name + ":";
  std::vector<std::string> out;
  const std::size_t baseline = f.parameters.size() - static_cast<std::size_t>(share.num_params());
  for (std::size_t j = 0; j < f.parameters.size(); ++j) {
    const std::string& name = f.parameters[j].name;
    bool shared = j < baseline && std::find(errors.begin(), errors.end(), name) != errors.end();
    if (j >= baseline)
      for (const Effect& e : share.effects)
        if (is_machine_effect(e) && is_parameter_of(name, e.id())) shared = true;
    out.push_back(shared ? name : prefix + name);
  }
  return out;
}

// min |W (b - J theta)|^2 over the joint parameters theta, where session k's rows are its own
// fit linearised about its solution x_k: r_k(theta) = w_k (r_k + J_k x_k - J_k theta_k).
ModelFit MultiDiagnosisProblem::fit_gls(const EffectModel& effects,
                                        std::shared_ptr<const ResidualWhitener> noise) const {
  const std::size_t K = sessions_.size();
  std::vector<EffectModel> shares;
  std::vector<const ModelFit*> fits;
  std::vector<std::vector<std::string>> names_of;
  for (std::size_t k = 0; k < K; ++k) {
    shares.push_back(share(k, effects));
    fits.push_back(&session_fit(k, shares.back()));
    names_of.push_back(joint_names(k, shares.back(), *fits.back()));
  }
  // The joint vector: location errors, each session's own baseline parameters, then the
  // effects' parameters in the model's order.
  std::vector<std::string> names, units;
  std::map<std::string, Eigen::Index> index;
  const auto add = [&](const std::string& name, const std::string& unit) {
    if (index.emplace(name, static_cast<Eigen::Index>(names.size())).second) {
      names.push_back(name);
      units.push_back(unit);
    }
  };
  const auto& errors = location_error_names(machine_);
  for (const std::string& e : errors)
    for (std::size_t k = 0; k < K; ++k)
      for (std::size_t j = 0; j < names_of[k].size(); ++j)
        if (names_of[k][j] == e) add(e, fits[k]->parameters[j].unit);
  for (std::size_t k = 0; k < K; ++k) {
    const std::size_t baseline =
        fits[k]->parameters.size() - static_cast<std::size_t>(shares[k].num_params());
    for (std::size_t j = 0; j < baseline; ++j) add(names_of[k][j], fits[k]->parameters[j].unit);
  }
  for (const Effect& e : effects.effects)
    for (std::size_t k = 0; k < K; ++k)
      for (std::size_t j = 0; j < names_of[k].size(); ++j)
        if (is_parameter_of(names_of[k][j], e.id()))
          add(names_of[k][j], fits[k]->parameters[j].unit);

  const Eigen::Index n = offsets_.back(), p = static_cast<Eigen::Index>(names.size());
  // A parameter one session held (its readings cannot tell it from its other parameters: the
  // C-axis location errors of an A sweep at one C) that another determines: these readings
  // respond to it in the joint fit, by the derivative the session's fit kept (held_columns).
  std::vector<bool> free_somewhere(static_cast<std::size_t>(p), false);
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t j = 0; j < names_of[k].size(); ++j)
      if (std::find(fits[k]->held.begin(), fits[k]->held.end(), static_cast<Eigen::Index>(j)) ==
          fits[k]->held.end())
        free_somewhere[static_cast<std::size_t>(index.at(names_of[k][j]))] = true;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, p);
  Eigen::VectorXd b(n), x0 = Eigen::VectorXd::Zero(p);
  std::vector<bool> has_start(static_cast<std::size_t>(p), false);
  for (std::size_t k = 0; k < K; ++k) {
    const ModelFit& f = *fits[k];
    Eigen::MatrixXd Jk = f.jacobian;
    for (std::size_t i = 0; i < f.held.size(); ++i) {
      const std::string& name = names_of[k][static_cast<std::size_t>(f.held[i])];
      if (free_somewhere[static_cast<std::size_t>(index.at(name))])
        Jk.col(f.held[i]) = f.held_columns.col(static_cast<Eigen::Index>(i));
    }
    Eigen::VectorXd x(static_cast<Eigen::Index>(f.parameters.size()));
    for (std::size_t j = 0; j < f.parameters.size(); ++j) {
      const Eigen::Index c = index.at(names_of[k][j]);
      x[static_cast<Eigen::Index>(j)] = f.parameters[j].value;
      J.block(offsets_[k], c, rows(k), 1) += weights_[k] * Jk.col(static_cast<Eigen::Index>(j));
      if (!has_start[static_cast<std::size_t>(c)]) x0[c] = f.parameters[j].value;
      has_start[static_cast<std::size_t>(c)] = true;
    }
    b.segment(offsets_[k], rows(k)) = weights_[k] * (f.residuals + Jk * x);
  }
  b -= J * x0;  // the step from x0: min-norm where the joint readings cannot tell parameters apart
  std::vector<Eigen::Index> free;
  for (Eigen::Index c = 0; c < p; ++c)
    if (J.col(c).squaredNorm() > 0.0) free.push_back(c);
  Eigen::MatrixXd Jf(n, static_cast<Eigen::Index>(free.size()));
  for (std::size_t i = 0; i < free.size(); ++i)
    Jf.col(static_cast<Eigen::Index>(i)) = J.col(free[i]);
  // The fixed parameters' columns are zero: b holds their share as each session fixed them.
  Eigen::MatrixXd Jw = Jf, bw = b;
  if (noise) {
    noise->apply(Jw);
    noise->apply(bw);
  }
  // One decomposition decides both the step and which parameters are determined: a direction
  // whose singular value is below 1e-6 of the largest (1e-12 of the normal matrix's eigenvalues)
  // gets no step. A column-pivoted solve with its own, looser rank test took the pivot y, z of an
  // added axial_A arc (which no reading sees to first order) to 5660 and -5340 mm,
  // and the candidates' Jacobians, taken at that pivot, hid a 4 um sag the first session alone
  // finds (bench/diagnosis_loop.py, ballbar gravity_sag_A, seed 303).
  constexpr double kNullSingular = 1e-6;
  Eigen::BDCSVD<Eigen::MatrixXd> svd(Jw, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(kNullSingular);
  const Eigen::VectorXd theta_free = svd.solve(bw).col(0);
  Eigen::VectorXd theta = x0;
  for (std::size_t i = 0; i < free.size(); ++i)
    theta[free[i]] += theta_free[static_cast<Eigen::Index>(i)];

  ModelFit out;
  out.effects = effects;
  out.residuals = b - Jf * theta_free;
  out.num_free = static_cast<int>(svd.rank());
  // The covariance: the pseudo-inverse of the (whitened) normal matrix, in units of the
  // whitened residuals under GLS, else of the weighted rows' noise (the first session's).
  const Eigen::VectorXd sv = svd.singularValues();
  const Eigen::MatrixXd& V = svd.matrixV();
  const double tol = sv.size() ? sv.maxCoeff() * kNullSingular : 0.0;
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (sv[i] > tol) inv[i] = 1.0 / (sv[i] * sv[i]);
  const Eigen::MatrixXd C = V * inv.asDiagonal() * V.transpose();
  double sigma = 1.0;
  if (!noise) {
    const double dof = std::max(1.0, static_cast<double>(n - out.num_free));
    sigma = declared_ ? *declared_ * 1e-3 : std::sqrt(out.residuals.squaredNorm() / dof);
  }
  std::vector<double> std_of(static_cast<std::size_t>(p), 0.0);
  std::vector<bool> determined(static_cast<std::size_t>(p), false);
  for (std::size_t i = 0; i < free.size(); ++i) {
    const Eigen::Index c = static_cast<Eigen::Index>(i);
    std_of[static_cast<std::size_t>(free[i])] = sigma * std::sqrt(std::max(0.0, C(c, c)));
    double in_null = 1.0;  // its share of the directions the joint readings cannot see
    for (Eigen::Index v = 0; v < sv.size(); ++v)
      if (sv[v] > tol) in_null -= V(c, v) * V(c, v);
    determined[static_cast<std::size_t>(free[i])] = in_null < 1e-6;
  }
  out.jacobian = J;
  for (Eigen::Index c = 0; c < p; ++c) {
    ParameterEstimate e;
    e.name = names[static_cast<std::size_t>(c)];
    e.unit = units[static_cast<std::size_t>(c)];
    e.value = theta[c];
    e.std = std_of[static_cast<std::size_t>(c)];
    e.observable = determined[static_cast<std::size_t>(c)];
    out.parameters.push_back(e);
  }
  return out;
}

Eigen::MatrixXd MultiDiagnosisProblem::candidate_jacobian(const ModelFit& at,
                                                          const Effect& candidate) const {
  return candidate_jacobians(at, {candidate}).front();
}

// Each session's Jacobian of the candidates it models, at the joint values of its parameters,
// weighted as its readings; zero on the rows of the sessions that do not model one.
std::vector<Eigen::MatrixXd> MultiDiagnosisProblem::candidate_jacobians(
    const ModelFit& at, const std::vector<Effect>& candidates) const {
  std::vector<Eigen::MatrixXd> out;
  for (const Effect& c : candidates)
    out.push_back(Eigen::MatrixXd::Zero(offsets_.back(), c.num_params()));
  std::map<std::string, double> value;
  for (const ParameterEstimate& e : at.parameters) value[e.name] = e.value;
  for (std::size_t k = 0; k < sessions_.size(); ++k) {
    std::vector<Effect> mine;
    std::vector<std::size_t> where;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      Effect e = candidates[i];
      if (e.session.empty() ? !models(k, e) : e.session != sessions_[k].name) continue;
      e.session.clear();
      mine.push_back(e);
      where.push_back(i);
    }
    if (mine.empty()) continue;
    const EffectModel s = share(k, at.effects);
    const ModelFit& f = session_fit(k, s);
    const std::vector<std::string> names = joint_names(k, s, f);
    ModelFit at_k;
    at_k.effects = f.effects;
    at_k.parameters = f.parameters;
    for (std::size_t j = 0; j < names.size(); ++j) {
      const auto v = value.find(names[j]);
      if (v != value.end()) at_k.parameters[j].value = v->second;
    }
    const std::vector<Eigen::MatrixXd> Jk = sessions_[k].problem->candidate_jacobians(at_k, mine);
    for (std::size_t i = 0; i < mine.size(); ++i)
      out[where[i]].middleRows(offsets_[k], rows(k)) = weights_[k] * Jk[i];
  }
  return out;
}

MultiDiagnosis diagnose_sessions(std::vector<DiagnosisSession> sessions,
                                 const DiagnosisOptions& options) {
  if (sessions.size() < 2)
    throw InvalidArgument("diagnose: a diagnosis of several sessions needs at least two, got " +
                          std::to_string(sessions.size()));
  check_sessions(sessions);
  std::vector<std::string> notes = join_continuations(sessions);
  const MultiDiagnosisProblem P(std::move(sessions));
  DiagnosisOptions o = options;
  o.noise.pool_by_session = true;  // each instrument its own AR coefficients
  MultiDiagnosis out;
  out.notes = std::move(notes);
  out.diagnosis = diagnose(P, o);
  const Diagnosis& D = out.diagnosis;
  const auto rms_um = [](const Eigen::VectorXd& r) {
    return r.size() ? std::sqrt(r.squaredNorm() / static_cast<double>(r.size())) * 1e3 : 0.0;
  };
  for (std::size_t k = 0; k < P.num_sessions(); ++k) {
    MultiDiagnosis::Session s;
    s.name = P.session(k).name;
    s.instrument = P.session(k).problem->instrument();
    s.n = static_cast<std::size_t>(P.rows(k));
    s.noise_um = P.noise_um(k);
    s.weight = P.weight(k);
    s.rms_before_um = rms_um(D.baseline_fit.residuals.segment(P.offset(k), P.rows(k))) / s.weight;
    s.rms_after_um = rms_um(D.final_fit.residuals.segment(P.offset(k), P.rows(k))) / s.weight;
    out.sessions.push_back(std::move(s));
  }
  for (const Finding& F : D.findings)
    out.where.push_back(F.effect.session.empty() ? "machine" : F.effect.session);
  return out;
}

}  // namespace rotacal
