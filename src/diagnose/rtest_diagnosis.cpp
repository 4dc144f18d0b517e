// The R-test diagnosis problem: baseline + effects fitted through the joint-fit driver on the
// one R-test reading (rtest/model.hpp), and the candidates' Jacobians by Jets of it.
#include "rotacal/diagnose/rtest_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "candidate_jets.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/rtest/model.hpp"

namespace rotacal {

namespace {

// r = d_model + zero_setup - d_measured (mm), three per pose. Parameters: location errors (8),
// on a machine with head axes tool_offset_Z (minus the error of pivot_length + tool_length,
// a location parameter of the head as in the joint fit), probe zero per set-up (3 each),
// effect parameters.
class RtestEffectResiduals : public ResidualModel {
 public:
  RtestEffectResiduals(MachineType m, const Eigen::Matrix3Xd& xyz, const Eigen::Matrix3Xd& nest,
                       const Eigen::Matrix3Xd& d, const std::vector<RotaryAngles<double>>& angles,
                       const std::vector<double>& times, const std::vector<int>& setup_of, int S,
                       const EffectModel& fx)
      : m_(m), xyz_(xyz), nest_(nest), d_(d), angles_(angles), times_(times), setup_of_(setup_of),
        S_(S), fx_(fx), P_(fx.num_params()), L_(m.has_head() ? 9 : 8) {}
  Eigen::Index num_residuals() const override { return 3 * xyz_.cols(); }
  int num_parameters() const override { return L_ + 3 * S_ + P_; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    const auto f = [this](Eigen::Index i, const auto* p, auto* out) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      const std::size_t k = static_cast<std::size_t>(i);
      const T* zero = p + L_ + 3 * setup_of_[k];
      const Vec3<T> d = rtest_reading<T>(m_, LocationErrors<T>::from_ptr(p), fx_,
                                         P_ > 0 ? p + L_ + 3 * S_ : nullptr, xyz_.col(i), angles_[k],
                                         times_[k], nest_.col(i), L_ > 8 ? T(-p[8]) : T(0));
      for (int a = 0; a < 3; ++a) out[a] = d[a] + zero[a] - T(d_(a, i));
    };
    evaluate_with_jets(f, xyz_.cols(), 3, x, r, J);
  }

 private:
  MachineType m_;
  const Eigen::Matrix3Xd &xyz_, &nest_, &d_;
  const std::vector<RotaryAngles<double>>& angles_;
  const std::vector<double>& times_;
  const std::vector<int>& setup_of_;
  int S_;
  const EffectModel& fx_;
  int P_;
  int L_;  // location parameters: 8, or 9 with tool_offset_Z on a head machine
};

}  // namespace

RtestDiagnosisProblem::RtestDiagnosisProblem(RtestSession session) : session_(std::move(session)) {
  setups_ = session_.setups();
  const Eigen::Index n = static_cast<Eigen::Index>(session_.samples.size());
  xyz_.resize(3, n), nest_.resize(3, n), d_.resize(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const RtestSample& s = session_.samples[static_cast<std::size_t>(i)];
    if (!s.d) throw InvalidArgument("diagnose_rtest: the session has no dx,dy,dz (convert raw probe readings first)");
    if (!session_.nests.count(s.setup))
      throw InvalidArgument("diagnose_rtest: session.nests: no nest." + s.setup);
    setup_of_.push_back(static_cast<int>(std::find(setups_.begin(), setups_.end(), s.setup) - setups_.begin()));
    xyz_.col(i) = s.xyz;
    nest_.col(i) = session_.nests.at(s.setup);
    d_.col(i) = *s.d;
    pose_angles_.push_back(s.angles_rad());
    pose_times_.push_back(s.time);
    for (int k = 0; k < 3; ++k) {
      groups_.push_back("nest " + s.setup);
      times_.push_back(s.time);
      angles_.push_back(s.angles_rad());
    }
  }
}

std::vector<Effect> RtestDiagnosisProblem::candidates(int max_harmonic) const {
  std::vector<Effect> out;
  // On a head machine tool_offset_Z is in the baseline (a location parameter of the head).
  const bool head = session_.machine.has_head();
  for (const Effect& e : effect_catalogue(session_.machine, max_harmonic))
    // The probes read static poses: the effects of the motion itself are zero there.
    if (e.kind != EffectKind::ballbar_length_offset && e.kind != EffectKind::ballbar_thermal_drift &&
        !(head && e.kind == EffectKind::tool_offset_Z) && !e.depends_on_motion())
      out.push_back(e);
  return out;
}

ModelFit RtestDiagnosisProblem::fit_gls(const EffectModel& effects,
                                        std::shared_ptr<const ResidualWhitener> noise) const {
  const EffectModel fx = centred_on(effects, session_.samples);
  const int S = static_cast<int>(setups_.size());
  std::vector<FitParameter> params;
  for (int k = 0; k < 8; ++k)
    params.push_back({location_error_names(session_.machine)[static_cast<std::size_t>(k)],
                      location_error_is_angle(k) ? "rad" : "mm", 0.0});
  if (session_.machine.has_head()) params.push_back({"tool_offset_Z", "mm", 0.0});
  for (const std::string& s : setups_)
    for (const char* a : {"x", "y", "z"}) params.push_back({"zero." + s + "." + a, "mm", 0.0});
  // Catalogue effects yield to the baseline where they share directions with it
  // (core/yield_convention.hpp: a first-order wobble of C is half an axis tilt).
  for (const Effect& f : fx.effects) {
    const auto pn = f.param_names(), pu = f.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      params.push_back({f.id() + (pn.size() > 1 ? "." + pn[k] : ""), pu[k], 0.0, 0.0, false, true});
  }
  JointFitSettings settings;
  settings.sigma = session_.noise_um.value_or(1.0) * 1e-3;
  settings.whitener = std::move(noise);
  const RtestEffectResiduals model(session_.machine, xyz_, nest_, d_, pose_angles_, pose_times_,
                                   setup_of_, S, fx);
  JointFitOutcome fit = solve_joint(model, params, settings);

  ModelFit out;
  out.effects = fx;
  out.residuals = std::move(fit.residuals);  // measured - model
  out.jacobian = std::move(fit.jacobian);
  out.num_free = fit.summary.num_free;
  for (std::size_t j = 0; j < fit.free.size(); ++j)
    if (!fit.free[j]) out.jacobian.col(static_cast<Eigen::Index>(j)).setZero();
  out.parameters = std::move(fit.estimates);
  return out;
}

namespace {

// d reading / d (the seeded parameters of `candidate`), three rows per pose: Jets of width N
// through the one R-test model, the current model's values as constants, the candidate
// appended with its parameters at 0 (candidate_jets.hpp). The probe zeros are additive: they
// do not change the derivative.
template <int N>
Eigen::MatrixXd reading_jets(MachineType m, const Eigen::Matrix3Xd& xyz, const Eigen::Matrix3Xd& nest,
                             const std::vector<RotaryAngles<double>>& angles, const std::vector<double>& times,
                             std::size_t setups, const ModelFit& at, const Effect& candidate,
                             const std::vector<int>& seed) {
  using Jet = ceres::Jet<double, N>;
  EffectModel fx = at.effects;
  fx.effects.push_back(candidate);
  LocationErrors<Jet> e;
  for (int i = 0; i < 8; ++i) e.v[i] = Jet(at.parameters[static_cast<std::size_t>(i)].value);
  const std::size_t L = m.has_head() ? 9 : 8;
  const Jet tool_length_error(L > 8 ? -at.parameters[8].value : 0.0);
  std::vector<Jet> p;
  for (std::size_t i = L + 3 * setups; i < at.parameters.size(); ++i) p.emplace_back(at.parameters[i].value);
  const std::size_t first = p.size();
  p.resize(first + static_cast<std::size_t>(candidate.num_params()), Jet(0.0));
  for (std::size_t k = 0; k < seed.size(); ++k) p[first + static_cast<std::size_t>(seed[k])] = Jet(0.0, static_cast<int>(k));
  Eigen::MatrixXd out(3 * xyz.cols(), static_cast<Eigen::Index>(seed.size()));
  for (Eigen::Index r = 0; r < xyz.cols(); ++r) {
    const std::size_t ri = static_cast<std::size_t>(r);
    const Vec3<Jet> d = rtest_reading<Jet>(m, e, fx, p.data(), xyz.col(r), angles[ri], times[ri], nest.col(r),
                                           tool_length_error);
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < seed.size(); ++k) out(3 * r + a, static_cast<Eigen::Index>(k)) = d[a].v[static_cast<Eigen::Index>(k)];
  }
  return out;
}

}  // namespace

// jets(width, effect, seed) for candidate_jets.hpp.
auto RtestDiagnosisProblem::jets_at(const ModelFit& at) const {
  return [this, &at](auto width, const Effect& effect, const std::vector<int>& seed) {
    return reading_jets<decltype(width)::value>(session_.machine, xyz_, nest_, pose_angles_, pose_times_,
                                                setups_.size(), at, effect, seed);
  };
}

Eigen::MatrixXd RtestDiagnosisProblem::candidate_jacobian(const ModelFit& at, const Effect& candidate) const {
  return candidate_jacobians(at, {candidate}).front();
}

std::vector<Eigen::MatrixXd> RtestDiagnosisProblem::candidate_jacobians(const ModelFit& at,
                                                                        const std::vector<Effect>& candidates) const {
  return diagnosis_detail::jacobians_of_candidates(
      session_.machine, candidates, jets_at(at),
      [&](Eigen::Index row) { return pose_angles_[static_cast<std::size_t>(row / 3)]; });
}

Eigen::MatrixXd RtestDiagnosisProblem::candidate_jacobian_by_jets(const ModelFit& at, const Effect& candidate) const {
  return diagnosis_detail::jets_of_width(candidate, diagnosis_detail::all_parameters(candidate), jets_at(at));
}

Diagnosis diagnose_rtest(const RtestSession& session, const DiagnosisOptions& options) {
  return diagnose(RtestDiagnosisProblem(session), options);
}

}  // namespace rotacal
