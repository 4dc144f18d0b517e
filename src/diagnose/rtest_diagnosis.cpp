#include "rotacal/diagnose/rtest_diagnosis.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "rotacal/core/least_squares.hpp"
#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

namespace {

// Predicted displacement of the sphere relative to the nest, table frame (Oyama Eq. 4).
template <typename T>
Vec3<T> predicted_displacement(MachineType m, const LocationErrors<T>& e, const T* zero, const EffectModel& fx,
                               const T* fxp, const RtestSample& s, const Eigen::Vector3d& nest) {
  const Pose<T> table = table_pose(m, e, fx, fxp, s.angles_rad(), s.time);
  const Vec3<T> tool = tool_position(fx, fxp, s.xyz, s.time);
  return table.inverse() * tool - nest.cast<T>() + Vec3<T>(zero[0], zero[1], zero[2]);
}

// r = (d_model - d_measured) / sigma, three per pose. Blocks: location errors (8), this
// set-up's probe zero (3), effect parameters (P >= 1; a constant dummy when P = 0).
struct RtestReadingResidual {
  RtestReadingResidual(MachineType m, const RtestSample& s, const Eigen::Vector3d& nest, const EffectModel& fx,
                       double inv_sigma)
      : machine_(m), sample_(s), nest_(nest), effects_(fx), inv_sigma_(inv_sigma) {}

  template <typename T>
  bool operator()(T const* const* p, T* r) const {
    const Vec3<T> d = predicted_displacement(machine_, LocationErrors<T>::from_ptr(p[0]), p[1], effects_, p[2],
                                             sample_, nest_);
    for (int k = 0; k < 3; ++k) r[k] = (d[k] - T((*sample_.d)[k])) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(MachineType m, const RtestSample& s, const Eigen::Vector3d& nest,
                                     const EffectModel& fx, double inv_sigma, int n_fx) {
    auto* c = new ceres::DynamicAutoDiffCostFunction<RtestReadingResidual, 16>(
        new RtestReadingResidual(m, s, nest, fx, inv_sigma));
    c->AddParameterBlock(8);
    c->AddParameterBlock(3);
    c->AddParameterBlock(n_fx);
    c->SetNumResiduals(3);
    return c;
  }

 private:
  MachineType machine_;
  RtestSample sample_;
  Eigen::Vector3d nest_;
  const EffectModel& effects_;
  double inv_sigma_;
};

}  // namespace

RtestDiagnosisProblem::RtestDiagnosisProblem(RtestSession session) : session_(std::move(session)) {
  setups_ = session_.setups();
  for (const RtestSample& s : session_.samples) {
    if (!s.d) throw InvalidArgument("diagnose_rtest: the session has no dx,dy,dz (convert raw probe readings first)");
    setup_of_.push_back(static_cast<int>(std::find(setups_.begin(), setups_.end(), s.setup) - setups_.begin()));
    for (int k = 0; k < 3; ++k) {
      groups_.push_back("nest " + s.setup);
      times_.push_back(s.time);
      angles_.push_back(s.angles_rad());
    }
  }
}

std::vector<Effect> RtestDiagnosisProblem::candidates(int max_harmonic) const {
  std::vector<Effect> out;
  for (const Effect& e : effect_catalogue(session_.machine, max_harmonic))
    if (e.kind != EffectKind::ballbar_length_offset && e.kind != EffectKind::ballbar_thermal_drift) out.push_back(e);
  return out;
}

ModelFit RtestDiagnosisProblem::fit(const EffectModel& fx) const {
  const int P = fx.num_params();
  const int S = static_cast<int>(setups_.size());
  const int n_par = 8 + 3 * S + P;
  const double sigma_mm = session_.noise_um.value_or(1.0) * 1e-3;
  Eigen::Matrix<double, 8, 1> e = Eigen::Matrix<double, 8, 1>::Zero();
  std::vector<Eigen::Vector3d> zeros(static_cast<std::size_t>(S), Eigen::Vector3d::Zero());
  std::vector<double> fxp(static_cast<std::size_t>(std::max(P, 1)), 0.0);

  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // evaluate_jacobian detaches them
  ceres::Problem problem(po);
  std::vector<std::unique_ptr<ceres::Manifold>> manifolds;
  for (std::size_t i = 0; i < session_.samples.size(); ++i) {
    const RtestSample& s = session_.samples[i];
    problem.AddResidualBlock(
        RtestReadingResidual::Create(session_.machine, s, session_.nests.at(s.setup), fx, 1.0 / sigma_mm,
                                     static_cast<int>(fxp.size())),
        nullptr, {e.data(), zeros[static_cast<std::size_t>(setup_of_[i])].data(), fxp.data()});
  }
  if (P == 0) problem.SetParameterBlockConstant(fxp.data());
  std::vector<double*> blocks = {e.data()};
  for (auto& z : zeros) blocks.push_back(z.data());
  blocks.push_back(fxp.data());

  std::vector<std::string> names, units;
  for (int k = 0; k < 8; ++k) {
    names.push_back(location_error_names(session_.machine)[static_cast<std::size_t>(k)]);
    units.push_back(location_error_is_angle(k) ? "rad" : "mm");
  }
  for (const std::string& s : setups_)
    for (const char* a : {"x", "y", "z"}) names.push_back("zero." + s + "." + a), units.push_back("mm");
  for (const Effect& f : fx.effects) {
    const auto pn = f.param_names(), pu = f.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      names.push_back(f.id() + (pn.size() > 1 ? "." + pn[k] : "")), units.push_back(pu[k]);
  }

  // Observability where the solver starts; hold one parameter per invisible combination.
  Eigen::VectorXd scales(n_par);
  for (int j = 0; j < n_par; ++j) scales[j] = plausible_magnitude(units[static_cast<std::size_t>(j)]);
  const Observability obs = analyse_observability(evaluate_jacobian(problem, blocks).leftCols(n_par), scales);
  std::vector<bool> free(static_cast<std::size_t>(n_par), true);
  for (int j : obs.to_fix) free[static_cast<std::size_t>(j)] = false;
  std::vector<std::pair<double*, int>> sized = {{e.data(), 8}};
  for (auto& z : zeros) sized.emplace_back(z.data(), 3);
  if (P > 0) sized.emplace_back(fxp.data(), P);
  hold_fixed(problem, sized, free, manifolds);

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 100;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  Eigen::VectorXd r;
  const Eigen::MatrixXd J = evaluate_jacobian(problem, blocks, &r).leftCols(n_par);
  ModelFit out;
  out.effects = fx;
  out.residuals = -r * sigma_mm;  // measured - model
  out.jacobian = J * sigma_mm;
  const double ss = out.residuals.squaredNorm();
  int n_free = 0;
  for (bool f : free) n_free += f;
  out.num_free = n_free;
  const double s2 = ss / std::max(1.0, static_cast<double>(r.size() - n_free));
  const Eigen::MatrixXd cov = covariance_from_jacobian(J, free, s2 / (sigma_mm * sigma_mm));
  std::vector<double> values(e.data(), e.data() + 8);
  for (const auto& z : zeros) values.insert(values.end(), z.data(), z.data() + 3);
  values.insert(values.end(), fxp.begin(), fxp.begin() + P);
  for (int j = 0; j < n_par; ++j) {
    if (!free[static_cast<std::size_t>(j)]) out.jacobian.col(j).setZero();
    ParameterEstimate p;
    p.name = names[static_cast<std::size_t>(j)];
    p.unit = units[static_cast<std::size_t>(j)];
    p.value = values[static_cast<std::size_t>(j)];
    p.std = std::sqrt(std::max(0.0, cov(j, j)));
    p.observable = obs.observable[static_cast<std::size_t>(j)];
    out.parameters.push_back(p);
  }
  return out;
}

Eigen::MatrixXd RtestDiagnosisProblem::candidate_jacobian(const ModelFit& at, const Effect& candidate) const {
  using J4 = ceres::Jet<double, 4>;
  const int k = candidate.num_params();
  const int S = static_cast<int>(setups_.size());
  EffectModel fx = at.effects;
  fx.effects.push_back(candidate);
  LocationErrors<J4> e;
  for (int i = 0; i < 8; ++i) e.v[i] = J4(at.parameters[static_cast<std::size_t>(i)].value);
  std::vector<J4> p;
  for (std::size_t i = 8 + 3 * static_cast<std::size_t>(S); i < at.parameters.size(); ++i)
    p.emplace_back(at.parameters[i].value);
  for (int i = 0; i < k; ++i) p.emplace_back(0.0, i);
  Eigen::MatrixXd out(3 * static_cast<Eigen::Index>(session_.samples.size()), k);
  for (std::size_t r = 0; r < session_.samples.size(); ++r) {
    const RtestSample& s = session_.samples[r];
    std::array<J4, 3> zero;
    for (int a = 0; a < 3; ++a)
      zero[static_cast<std::size_t>(a)] = J4(at.parameters[8 + 3 * static_cast<std::size_t>(setup_of_[r]) + static_cast<std::size_t>(a)].value);
    const Vec3<J4> d = predicted_displacement(session_.machine, e, zero.data(), fx, p.data(), s, session_.nests.at(s.setup));
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < k; ++i) out(3 * static_cast<Eigen::Index>(r) + a, i) = d[a].v[i];
  }
  return out;
}

Diagnosis diagnose_rtest(const RtestSession& session, const DiagnosisOptions& options) {
  return diagnose(RtestDiagnosisProblem(session), options);
}

}  // namespace rotacal
