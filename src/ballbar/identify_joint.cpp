#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/least_squares.hpp"

namespace rotacal {

const ParameterEstimate& BallbarIdentification::parameter(const std::string& name) const {
  for (const ParameterEstimate& p : parameters)
    if (p.name == name) return p;
  throw InvalidArgument("no identified parameter named '" + name + "'");
}

namespace {

// r = (L_model - L_measured) / sigma for one sample. Parameter blocks: location errors (8),
// pivot (3), effect parameters (P >= 1; a dummy of size 1 when there are none, held constant).
struct BallbarLengthResidual {
  BallbarLengthResidual(MachineType m, const BallbarSample& s, const EffectModel& fx,
                        double inv_sigma)
      : machine_(m), sample_(s), effects_(fx), inv_sigma_(inv_sigma) {}

  // With effects: blocks (errors, pivot, effect parameters), sizes known at run time.
  template <typename T>
  bool operator()(T const* const* p, T* residual) const {
    return (*this)(p[0], p[1], p[2], residual);
  }

  // Without effects (the usual case): fixed sizes, so Ceres uses Jet<double, 11>.
  template <typename T>
  bool operator()(const T* errors, const T* pivot, T* residual) const {
    return (*this)(errors, pivot, static_cast<const T*>(nullptr), residual);
  }

  template <typename T>
  bool operator()(const T* errors, const T* pivot_ptr, const T* effect_params, T* residual) const {
    const LocationErrors<T> e = LocationErrors<T>::from_ptr(errors);
    const Vec3<T> pivot(pivot_ptr[0], pivot_ptr[1], pivot_ptr[2]);
    const T L = predicted_length<T>(machine_, e, pivot, effects_, effect_params, sample_);
    residual[0] = (L - T(sample_.length)) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(MachineType m, const BallbarSample& s, const EffectModel& fx,
                                     double inv_sigma, int n_effect_params) {
    if (fx.effects.empty())
      return new ceres::AutoDiffCostFunction<BallbarLengthResidual, 1, 8, 3>(
          new BallbarLengthResidual(m, s, fx, inv_sigma));
    auto* cost = new ceres::DynamicAutoDiffCostFunction<BallbarLengthResidual, 16>(
        new BallbarLengthResidual(m, s, fx, inv_sigma));
    cost->AddParameterBlock(8);
    cost->AddParameterBlock(3);
    cost->AddParameterBlock(n_effect_params);
    cost->SetNumResiduals(1);
    return cost;
  }

 private:
  MachineType machine_;
  BallbarSample sample_;
  const EffectModel& effects_;  // outlives the problem: owned by identify_joint
  double inv_sigma_;
};

}  // namespace

BallbarIdentification identify_joint(const BallbarSession& session,
                                     const JointFitOptions& options) {
  EffectModel fx = options.effects;
  if (options.fit_length_offset)
    fx.effects.insert(fx.effects.begin(), Effect::parse("ballbar_length_offset"));
  for (const Effect& f : fx.effects)
    if (!f.applies_to(session.machine))
      throw InvalidArgument("effect " + f.id() + " does not exist on a " + to_string(session.machine));

  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < session.samples.size(); ++i)
    if (options.tests.empty() ||
        std::find(options.tests.begin(), options.tests.end(), session.samples[i].test) !=
            options.tests.end())
      used.push_back(i);
  const int P = fx.num_params();
  const int n_par = 8 + 3 + P;
  if (static_cast<int>(used.size()) < n_par)
    throw InvalidArgument("identify_joint: " + std::to_string(used.size()) +
                          " samples cannot determine " + std::to_string(n_par) + " unknowns");

  // sigma only scales the cost; the covariance uses the residual variance below.
  const double sigma_mm = session.noise_um.value_or(1.0) * 1e-3;
  Eigen::Matrix<double, 8, 1> e = Eigen::Matrix<double, 8, 1>::Zero();
  Eigen::Vector3d pivot = session.pivot;
  std::vector<double> fxp(static_cast<std::size_t>(std::max(P, 1)), 0.0);

  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // evaluate_jacobian detaches them
  ceres::Problem problem(po);
  std::vector<std::unique_ptr<ceres::Manifold>> manifolds;
  for (std::size_t i : used) {
    ceres::CostFunction* cost = BallbarLengthResidual::Create(
        session.machine, session.samples[i], fx, 1.0 / sigma_mm, static_cast<int>(fxp.size()));
    if (P == 0)
      problem.AddResidualBlock(cost, nullptr, e.data(), pivot.data());
    else
      problem.AddResidualBlock(cost, nullptr, {e.data(), pivot.data(), fxp.data()});
  }

  // Names and units of the unknowns, in Jacobian column order.
  std::vector<std::string> names, units;
  for (int k = 0; k < 8; ++k) {
    names.push_back(location_error_names(session.machine)[static_cast<std::size_t>(k)]);
    units.push_back(location_error_is_angle(k) ? "rad" : "mm");
  }
  for (const char* c : {"pivot_x", "pivot_y", "pivot_z"}) names.push_back(c), units.push_back("mm");
  for (const Effect& f : fx.effects) {
    const auto pn = f.param_names(), pu = f.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      names.push_back(f.id() + (pn.size() > 1 ? "." + pn[k] : "")), units.push_back(pu[k]);
  }
  std::vector<double*> blocks = {e.data(), pivot.data()};
  if (P > 0) blocks.push_back(fxp.data());

  // Observability at the start point (the model is nearly linear over um-sized errors): fix
  // one parameter per invisible combination so the solver does not wander along it.
  const Eigen::MatrixXd J0 = evaluate_jacobian(problem, blocks).leftCols(n_par);
  Eigen::VectorXd scales(n_par);
  for (int j = 0; j < n_par; ++j) scales[j] = plausible_magnitude(units[static_cast<std::size_t>(j)]);
  // J0 is in units of 1/sigma_mm with sigma from the file (or 1 um): chi-square units.
  const Observability obs = analyse_observability(J0, scales, options.observability_min_chi2);
  std::vector<bool> free(static_cast<std::size_t>(n_par), true);
  for (int j : obs.to_fix) free[static_cast<std::size_t>(j)] = false;
  std::vector<std::pair<double*, int>> sized = {{e.data(), 8}, {pivot.data(), 3}};
  if (P > 0) sized.emplace_back(fxp.data(), P);
  hold_fixed(problem, sized, free, manifolds);

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  BallbarIdentification out;
  out.method = "joint";
  out.model.machine = session.machine;
  out.model.errors = LocationErrors<double>(e);
  out.model.pivot = pivot;
  out.model.effects = fx;
  out.model.effect_params.assign(fxp.begin(), fxp.begin() + P);
  out.converged = summary.IsSolutionUsable() &&
                  summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.n_samples = used.size();

  Eigen::VectorXd r;
  const Eigen::MatrixXd J = evaluate_jacobian(problem, blocks, &r).leftCols(n_par);
  out.residuals.assign(session.samples.size(), 0.0);
  double ss = 0.0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    const double res_mm = -r[static_cast<Eigen::Index>(k)] * sigma_mm;  // measured - model
    out.residuals[used[k]] = res_mm;
    ss += res_mm * res_mm;
  }
  out.residual_rms_um = std::sqrt(ss / static_cast<double>(used.size())) * 1e3;
  int n_free = 0;
  for (bool f : free) n_free += f;
  const double dof = static_cast<double>(used.size()) - n_free;
  const double s2_mm = ss / std::max(dof, 1.0);
  out.sigma_um = std::sqrt(s2_mm) * 1e3;
  // J is in units of 1/sigma_mm; (J^T J)^-1 * sigma_mm^2 is the covariance at unit variance
  // ratio, scaled by the residual variance.
  out.covariance = covariance_from_jacobian(J, free, s2_mm / (sigma_mm * sigma_mm));
  out.jacobian = J * sigma_mm;  // back from weighted residuals to mm
  for (bool f : free) out.fixed.push_back(!f);

  const std::vector<double> values = [&] {
    std::vector<double> v(e.data(), e.data() + 8);
    v.insert(v.end(), pivot.data(), pivot.data() + 3);
    v.insert(v.end(), fxp.begin(), fxp.begin() + P);
    return v;
  }();
  for (int j = 0; j < n_par; ++j) {
    ParameterEstimate p;
    p.name = names[static_cast<std::size_t>(j)];
    p.unit = units[static_cast<std::size_t>(j)];
    p.value = values[static_cast<std::size_t>(j)];
    p.std = std::sqrt(std::max(0.0, out.covariance(j, j)));
    p.observable = obs.observable[static_cast<std::size_t>(j)];
    out.parameters.push_back(p);
  }
  for (std::size_t k = 0; k < obs.null_space.size(); ++k)
    out.unobservable.push_back(obs.describe(static_cast<int>(k), names, units));
  if (!out.converged) out.notes.push_back("Ceres did not converge: " + summary.message);
  return out;
}

}  // namespace rotacal
