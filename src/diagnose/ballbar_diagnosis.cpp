// SPDX-License-Identifier: BSD-3-Clause
// The ballbar diagnosis problem: baseline + effects by the joint fit on arrays built once,
// and the candidates' Jacobians by Jets of the one length model.
#include "rotacal/diagnose/ballbar_diagnosis.hpp"

#include <ceres/jet.h>

#include "ballbar_sensitivities.hpp"
#include "candidate_jets.hpp"
#include "rotacal/ballbar/problem.hpp"

namespace rotacal {

BallbarDiagnosisProblem::BallbarDiagnosisProblem(BallbarSession session, BallbarSession reference)
    : session_(std::move(session)),
      arrays_(ballbar_arrays(session_)),
      reference_(std::move(reference)),
      reference_motion_(rotary_motion(reference_.samples)),
      places_(std::make_shared<diagnosis_detail::BallbarPlacesCache>()) {
  times_.assign(arrays_.time.data(), arrays_.time.data() + arrays_.time.size());
  if (!reference_.samples.empty() && reference_.machine != session_.machine)
    throw InvalidArgument("reference test is for " + to_string(reference_.machine) +
                          " but the session is for " + to_string(session_.machine));
}

std::vector<Effect> BallbarDiagnosisProblem::candidates(int max_harmonic) const {
  // An axis' motion effects are candidates only where it moved both ways: in one direction
  // (every test of the standard plan) each is a constant angle offset, the zero offset that
  // no radial or axial test sees, and testing them would only cost time.
  // Only the tests count: a recording keeps its transitions, which turn the axes back to 0.
  bool both_ways[2] = {false, false};
  for (int k = 0; k < 2; ++k) {
    bool up = false, down = false;
    for (std::size_t i = 0; i < arrays_.motion.size(); ++i) {
      if (arrays_.test[i] == "transition") continue;
      const RotaryMotion& m = arrays_.motion[i];
      const double d = k == 0 ? m.rate.tilt : m.rate.rot;
      up = up || d > 0.0;
      down = down || d < 0.0;
    }
    both_ways[k] = up && down;
  }
  std::vector<Effect> out;
  for (const Effect& e : effect_catalogue(session_.machine, max_harmonic))
    if (!e.depends_on_motion() || both_ways[e.axis == rot_axis_letter(session_.machine) ? 1 : 0])
      out.push_back(e);
  return out;
}

ModelFit BallbarDiagnosisProblem::fit_gls(const EffectModel& effects,
                                          std::shared_ptr<const ResidualWhitener> noise) const {
  JointFitOptions o;
  o.effects = effects;
  o.whitener = std::move(noise);
  BallbarIdentification id = identify_joint(arrays_, o);  // its Jacobian is moved, not copied
  ModelFit f;
  f.effects = id.model.effects;
  f.parameters = id.parameters;
  f.residuals = Eigen::Map<const Eigen::VectorXd>(id.residuals.data(),
                                                  static_cast<Eigen::Index>(id.residuals.size()));
  f.jacobian = std::move(id.jacobian);
  std::vector<bool> held(id.fixed.size());
  for (std::size_t j = 0; j < id.fixed.size(); ++j) {
    held[j] = id.fixed[j];
    if (!held[j]) ++f.num_free;
  }
  f.hold(held);
  return f;
}

namespace {

// d L / d (the seeded parameters of `candidate`) on `samples`: Jets of width N through the
// problem's one residual, the current model's values as constants, the candidate appended
// with its parameters at 0 (candidate_jets.hpp).
template <int N>
Eigen::MatrixXd length_jets(MachineType m, const std::vector<BallbarSample>& samples,
                            const std::vector<RotaryMotion>& motion, const ModelFit& at,
                            const Effect& candidate, const std::vector<int>& seed) {
  using Jet = ceres::Jet<double, N>;
  EffectModel fx = at.effects;
  fx.effects.push_back(candidate);
  const BallbarLayout L = ballbar_layout(m, fx);
  std::vector<Jet> p(static_cast<std::size_t>(L.all.size()), Jet(0.0));
  for (std::size_t i = 0; i < at.parameters.size(); ++i) p[i] = Jet(at.parameters[i].value);
  const std::size_t first = at.parameters.size();  // the candidate's parameters: the layout's last
  for (std::size_t k = 0; k < seed.size(); ++k)
    p[first + static_cast<std::size_t>(seed[k])] = Jet(0.0, static_cast<int>(k));
  Eigen::MatrixXd out(static_cast<Eigen::Index>(samples.size()),
                      static_cast<Eigen::Index>(seed.size()));
  for (std::size_t r = 0; r < samples.size(); ++r) {
    const BallbarSample& s = samples[r];
    const Jet L_r =
        ballbar_residual<Jet>(L, m, fx, p.data(), 0, s.xyz, s.angles_rad(), s.time, motion[r], 0.0);
    for (std::size_t k = 0; k < seed.size(); ++k)
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) =
          L_r.v[static_cast<Eigen::Index>(k)];
  }
  return out;
}

// jets(width, effect, seed) for candidate_jets.hpp, by Jets of width 4 whatever the seed (the
// head machines' and the tests' path since the chain rule: one instantiation builds faster).
auto jets_on(MachineType m, const std::vector<BallbarSample>& samples,
             const std::vector<RotaryMotion>& motion, const ModelFit& at) {
  return [&, m](auto /*width*/, const Effect& effect, const std::vector<int>& seed) {
    return length_jets<4>(m, samples, motion, at, effect, seed);
  };
}

// The same by the chain rule at the fit of `S`, on machines it supports; the candidates' own
// places kept in `cache` when given (the session's rows).
auto chain_rule_on(const diagnosis_detail::BallbarSensitivities& S,
                   diagnosis_detail::BallbarPlacesCache* cache) {
  return [&S, cache](auto /*width*/, const Effect& effect, const std::vector<int>& seed) {
    if (!cache) return S.columns(S.places(effect, seed));
    return S.columns(*cache->get(S.key(effect, seed), [&] { return S.places(effect, seed); }));
  };
}

}  // namespace

Eigen::MatrixXd BallbarDiagnosisProblem::jacobian_on(const std::vector<BallbarSample>& samples,
                                                     const std::vector<RotaryMotion>& motion,
                                                     const ModelFit& at,
                                                     const Effect& candidate) const {
  const auto angles = [&](Eigen::Index r) {
    return samples[static_cast<std::size_t>(r)].angles_rad();
  };
  const MachineType m = session_.machine;
  if (!diagnosis_detail::BallbarSensitivities::supports(m))
    return diagnosis_detail::jacobian_of_candidate(m, candidate, jets_on(m, samples, motion, at),
                                                   angles);
  const diagnosis_detail::BallbarSensitivities S(m, samples, motion, at);
  return diagnosis_detail::jacobian_of_candidate(
      m, candidate, chain_rule_on(S, &samples == &session_.samples ? places_.get() : nullptr),
      angles);
}

std::vector<Eigen::MatrixXd> BallbarDiagnosisProblem::candidate_jacobians(
    const ModelFit& at, const std::vector<Effect>& candidates) const {
  const auto angles = [&](Eigen::Index r) { return arrays_.angles[static_cast<std::size_t>(r)]; };
  const MachineType m = session_.machine;
  if (!diagnosis_detail::BallbarSensitivities::supports(m))
    return diagnosis_detail::jacobians_of_candidates(
        m, candidates, jets_on(m, session_.samples, arrays_.motion, at), angles);
  // The fit's part of every row once for all candidates (ballbar_sensitivities.hpp).
  const diagnosis_detail::BallbarSensitivities S(m, session_.samples, arrays_.motion, at);
  return diagnosis_detail::jacobians_of_candidates(m, candidates, chain_rule_on(S, places_.get()),
                                                   angles);
}

void BallbarDiagnosisProblem::visit_candidate_jacobians(
    const ModelFit& at, const std::vector<Effect>& candidates,
    const std::function<void(std::size_t, const Eigen::MatrixXd&)>& visit) const {
  const auto angles = [&](Eigen::Index r) { return arrays_.angles[static_cast<std::size_t>(r)]; };
  const MachineType m = session_.machine;
  const auto each = [&](std::size_t i, const Eigen::MatrixXd& J) { visit(i, J); };
  if (!diagnosis_detail::BallbarSensitivities::supports(m))
    return diagnosis_detail::for_each_candidate(
        m, candidates, jets_on(m, session_.samples, arrays_.motion, at), angles, each);
  const diagnosis_detail::BallbarSensitivities S(m, session_.samples, arrays_.motion, at);
  // Each candidate visited once: the places are not kept (a long session's memory).
  diagnosis_detail::for_each_candidate(m, candidates, chain_rule_on(S, nullptr), angles, each);
}

namespace {

// Rows of a reduced design: every `stride`-th row, the last, and both sides of every break
// where a left-out effect may jump (a new test; an axis reversing, starting or stopping).
std::vector<std::size_t> design_rows(const BallbarArrays& a, std::size_t stride) {
  const std::size_t n = a.motion.size();
  const auto sign = [](double v) { return (v > 0.0) - (v < 0.0); };
  const auto jumps = [&](std::size_t i) {
    const RotaryMotion &p = a.motion[i - 1], &q = a.motion[i];
    return a.test[i] != a.test[i - 1] || sign(p.rate.tilt) != sign(q.rate.tilt) ||
           sign(p.rate.rot) != sign(q.rate.rot) || p.direction.tilt != q.direction.tilt ||
           p.direction.rot != q.direction.rot;
  };
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i)
    if (i % stride == 0 || i + 1 == n || (i > 0 && jumps(i)) || (i + 1 < n && jumps(i + 1)))
      out.push_back(i);
  return out;
}

}  // namespace

void BallbarDiagnosisProblem::visit_candidate_jacobians_reduced(
    const ModelFit& at, const std::vector<Effect>& candidates, std::size_t rows,
    const std::function<void(std::size_t, const Eigen::MatrixXd&)>& visit) const {
  const std::size_t n = session_.samples.size();
  if (rows == 0 || n <= 2 * rows) return visit_candidate_jacobians(at, candidates, visit);
  const std::vector<std::size_t> R = design_rows(arrays_, (n + rows - 1) / rows);
  std::vector<BallbarSample> samples;
  std::vector<RotaryMotion> motion;
  samples.reserve(R.size());
  motion.reserve(R.size());
  for (std::size_t r : R) {
    samples.push_back(session_.samples[r]);
    motion.push_back(arrays_.motion[r]);
  }
  // Linear in the row between two design rows (R holds row 0 and row n - 1).
  const auto each = [&](std::size_t i, const Eigen::MatrixXd& Jr) {
    Eigen::MatrixXd J(static_cast<Eigen::Index>(n), Jr.cols());
    for (std::size_t j = 0; j + 1 < R.size(); ++j) {
      const auto a = static_cast<Eigen::Index>(j);
      for (std::size_t r = R[j]; r < R[j + 1]; ++r) {
        const double w = static_cast<double>(r - R[j]) / static_cast<double>(R[j + 1] - R[j]);
        J.row(static_cast<Eigen::Index>(r)) = (1.0 - w) * Jr.row(a) + w * Jr.row(a + 1);
      }
    }
    J.row(static_cast<Eigen::Index>(n - 1)) = Jr.row(Jr.rows() - 1);
    visit(i, J);
  };
  const auto angles = [&](Eigen::Index r) {
    return samples[static_cast<std::size_t>(r)].angles_rad();
  };
  const MachineType m = session_.machine;
  if (!diagnosis_detail::BallbarSensitivities::supports(m))
    return diagnosis_detail::for_each_candidate(m, candidates, jets_on(m, samples, motion, at),
                                                angles, each);
  const diagnosis_detail::BallbarSensitivities S(m, samples, motion, at);
  diagnosis_detail::for_each_candidate(m, candidates, chain_rule_on(S, nullptr), angles, each);
}

Eigen::MatrixXd BallbarDiagnosisProblem::candidate_jacobian(const ModelFit& at,
                                                            const Effect& candidate) const {
  return jacobian_on(session_.samples, arrays_.motion, at, candidate);
}

Eigen::MatrixXd BallbarDiagnosisProblem::candidate_jacobian_by_jets(const ModelFit& at,
                                                                    const Effect& candidate) const {
  return diagnosis_detail::jets_of_width(
      candidate, diagnosis_detail::all_parameters(candidate),
      jets_on(session_.machine, session_.samples, arrays_.motion, at));
}

std::vector<std::string> BallbarDiagnosisProblem::reference_groups() const {
  return reference_.tests();
}

Eigen::MatrixXd BallbarDiagnosisProblem::reference_jacobian(const ModelFit& at,
                                                            const Effect& candidate,
                                                            std::vector<std::string>* rows) const {
  if (rows) {
    rows->clear();
    for (const BallbarSample& s : reference_.samples) rows->push_back(s.test);
  }
  return jacobian_on(reference_.samples, reference_motion_, at, candidate);
}

Diagnosis diagnose_ballbar(BallbarSession session, const DiagnosisOptions& options,
                           BallbarSession reference) {
  return diagnose(BallbarDiagnosisProblem(std::move(session), std::move(reference)), options);
}

Diagnosis budget_diagnosis_ballbar(const BallbarSession& session, const DiagnosisOptions& options,
                                   std::size_t design_rows) {
  const std::size_t n = session.samples.size();
  if (design_rows == 0 || n <= 2 * design_rows) return diagnose_ballbar(session, options);
  BallbarSession thin;  // the session's header, every k-th reading
  thin.machine = session.machine;
  thin.ballbar_length = session.ballbar_length;
  thin.pivot = session.pivot;
  thin.noise_um = session.noise_um;
  const std::size_t k = (n + design_rows - 1) / design_rows;
  thin.samples.reserve(n / k + 1);
  for (std::size_t i = 0; i < n; i += k) thin.samples.push_back(session.samples[i]);
  const Diagnosis searched = diagnose_ballbar(std::move(thin), options);
  DiagnosisOptions on_all = options;
  on_all.only.clear();
  for (const Finding& f : searched.findings) on_all.only.push_back(f.effect.id());
  if (on_all.only.empty()) on_all.max_findings = 0;  // only = {} would mean every candidate
  return diagnose_ballbar(session, on_all);
}

}  // namespace rotacal
