// The ballbar diagnosis problem: baseline + effects by the joint fit on arrays built once,
// and the candidates' Jacobians by Jets of the one length model.
#include "rotacal/diagnose/ballbar_diagnosis.hpp"

#include <ceres/jet.h>

namespace rotacal {

BallbarDiagnosisProblem::BallbarDiagnosisProblem(BallbarSession session, BallbarSession reference)
    : session_(std::move(session)),
      arrays_(ballbar_arrays(session_)),
      reference_(std::move(reference)),
      reference_motion_(rotary_motion(reference_.samples)) {
  for (const BallbarSample& s : session_.samples) {
    groups_.push_back(s.test);
    times_.push_back(s.time);
    angles_.push_back(s.angles_rad());
  }
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

ModelFit BallbarDiagnosisProblem::fit(const EffectModel& effects) const {
  JointFitOptions o;
  o.effects = effects;
  o.whitener = whitener;
  const BallbarIdentification id = identify_joint(arrays_, o);
  ModelFit f;
  f.effects = id.model.effects;
  f.parameters = id.parameters;
  f.residuals = Eigen::Map<const Eigen::VectorXd>(id.residuals.data(),
                                                  static_cast<Eigen::Index>(id.residuals.size()));
  f.jacobian = id.jacobian;
  for (std::size_t j = 0; j < id.fixed.size(); ++j) {
    if (id.fixed[j]) f.jacobian.col(static_cast<Eigen::Index>(j)).setZero();
    else ++f.num_free;
  }
  return f;
}

Eigen::MatrixXd BallbarDiagnosisProblem::jacobian_on(const std::vector<BallbarSample>& samples,
                                                     const std::vector<RotaryMotion>& motion,
                                                     const ModelFit& at,
                                                     const Effect& candidate) const {
  using J4 = ceres::Jet<double, 4>;
  const int k = candidate.num_params();
  // Current model with its parameter values as constants, the candidate's at zero, seeded.
  EffectModel fx = at.effects;
  fx.effects.push_back(candidate);
  std::vector<J4> p;
  LocationErrors<J4> e;
  for (int i = 0; i < 8; ++i) e.v[i] = J4(at.parameters[static_cast<std::size_t>(i)].value);
  const Vec3<J4> pivot(J4(at.parameters[8].value), J4(at.parameters[9].value),
                       J4(at.parameters[10].value));
  for (std::size_t i = 11; i < at.parameters.size(); ++i) p.emplace_back(at.parameters[i].value);
  for (int i = 0; i < k; ++i) p.emplace_back(0.0, i);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(samples.size()), k);
  for (std::size_t r = 0; r < samples.size(); ++r) {
    const J4 L = predicted_length<J4>(session_.machine, e, pivot, fx, p.data(), samples[r], motion[r]);
    for (int i = 0; i < k; ++i) out(static_cast<Eigen::Index>(r), i) = L.v[i];
  }
  return out;
}

Eigen::MatrixXd BallbarDiagnosisProblem::candidate_jacobian(const ModelFit& at,
                                                            const Effect& candidate) const {
  return jacobian_on(session_.samples, arrays_.motion, at, candidate);
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

Diagnosis diagnose_ballbar(const BallbarSession& session, const DiagnosisOptions& options,
                           const BallbarSession& reference) {
  return diagnose(BallbarDiagnosisProblem(session, reference), options);
}

}  // namespace rotacal
