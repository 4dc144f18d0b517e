// Joint ballbar fit: the exact length model (model.hpp) over structure-of-arrays samples,
// solved by the one joint-fit driver (core/joint_fit.hpp).
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/joint_fit.hpp"

namespace rotacal {

const ParameterEstimate& BallbarIdentification::parameter(const std::string& name) const {
  for (const ParameterEstimate& p : parameters)
    if (p.name == name) return p;
  throw InvalidArgument("no identified parameter named '" + name + "'");
}

BallbarArrays ballbar_arrays(const BallbarSession& session, const std::vector<std::string>& tests) {
  BallbarArrays a;
  a.machine = session.machine;
  a.pivot = session.pivot;
  a.noise_um = session.noise_um;
  a.session_size = session.samples.size();
  for (std::size_t i = 0; i < session.samples.size(); ++i)
    if (tests.empty() || std::find(tests.begin(), tests.end(), session.samples[i].test) != tests.end())
      a.index.push_back(i);
  const Eigen::Index n = static_cast<Eigen::Index>(a.index.size());
  a.xyz.resize(3, n);
  a.angles.resize(a.index.size());
  a.time.resize(n);
  a.length.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const BallbarSample& s = session.samples[a.index[static_cast<std::size_t>(k)]];
    a.xyz.col(k) = s.xyz;
    a.angles[static_cast<std::size_t>(k)] = s.angles_rad();
    a.time[k] = s.time;
    a.length[k] = s.length;
  }
  return a;
}

namespace {

// r_i = L_model,i - L_i (mm). Parameters: 8 location errors, pivot (3), effect parameters.
class BallbarLengthModel : public ResidualModel {
 public:
  BallbarLengthModel(const BallbarArrays& d, const EffectModel& fx)
      : d_(d), fx_(fx), P_(fx.num_params()) {}
  Eigen::Index num_residuals() const override { return d_.size(); }
  int num_parameters() const override { return 11 + P_; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    const auto f = [this](Eigen::Index i, const auto* p, auto* out) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      const Vec3<T> pivot(p[8], p[9], p[10]);
      const Eigen::Vector3d xyz = d_.xyz.col(i);
      out[0] = predicted_length<T>(d_.machine, LocationErrors<T>::from_ptr(p), pivot, fx_,
                                   P_ > 0 ? p + 11 : nullptr, xyz,
                                   d_.angles[static_cast<std::size_t>(i)], d_.time[i]) -
               T(d_.length[i]);
    };
    evaluate_with_jets(f, d_.size(), 1, x, r, J);
  }

 private:
  const BallbarArrays& d_;
  const EffectModel& fx_;
  int P_;
};

}  // namespace

BallbarIdentification identify_joint(const BallbarSession& session, const JointFitOptions& options) {
  return identify_joint(ballbar_arrays(session, options.tests), options);
}

BallbarIdentification identify_joint(const BallbarArrays& data, const JointFitOptions& options) {
  EffectModel fx = options.effects;
  if (options.fit_length_offset)
    fx.effects.insert(fx.effects.begin(), Effect::parse("ballbar_length_offset"));
  for (const Effect& f : fx.effects)
    if (!f.applies_to(data.machine))
      throw InvalidArgument("effect " + f.id() + " does not exist on a " + to_string(data.machine));
  const int P = fx.num_params();
  const int n_par = 8 + 3 + P;
  if (static_cast<int>(data.size()) < n_par)
    throw InvalidArgument("identify_joint: " + std::to_string(data.size()) +
                          " samples cannot determine " + std::to_string(n_par) + " unknowns");

  // Names, units and start values of the unknowns, in Jacobian column order.
  std::vector<FitParameter> params;
  for (int k = 0; k < 8; ++k)
    params.push_back({location_error_names(data.machine)[static_cast<std::size_t>(k)],
                      location_error_is_angle(k) ? "rad" : "mm", 0.0});
  const char* pivot_names[3] = {"pivot_x", "pivot_y", "pivot_z"};
  for (int k = 0; k < 3; ++k) params.push_back({pivot_names[k], "mm", data.pivot[k]});
  for (const Effect& f : fx.effects) {
    const auto pn = f.param_names(), pu = f.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      params.push_back({f.id() + (pn.size() > 1 ? "." + pn[k] : ""), pu[k], 0.0});
  }

  JointFitSettings settings;
  settings.max_iterations = options.max_iterations;
  settings.observability_min_chi2 = options.observability_min_chi2;
  // sigma scales chi-square (observability); the covariance uses the residual variance.
  settings.sigma = data.noise_um.value_or(1.0) * 1e-3;
  settings.whitener = options.whitener;
  const BallbarLengthModel model(data, fx);
  JointFitOutcome fit = solve_joint(model, params, settings);

  BallbarIdentification out;
  out.method = "joint";
  out.model.machine = data.machine;
  out.model.errors = LocationErrors<double>(fit.values.head<8>());
  out.model.pivot = fit.values.segment<3>(8);
  out.model.effects = fx;
  out.model.effect_params.assign(fit.values.data() + 11, fit.values.data() + 11 + P);
  out.converged = fit.summary.converged;
  out.iterations = fit.summary.iterations;
  out.n_samples = static_cast<std::size_t>(data.size());
  out.residuals.assign(data.session_size, 0.0);
  for (std::size_t k = 0; k < data.index.size(); ++k)
    out.residuals[data.index[k]] = fit.residuals[static_cast<Eigen::Index>(k)];
  out.residual_rms_um = std::sqrt(fit.residuals.squaredNorm() / static_cast<double>(data.size())) * 1e3;
  out.sigma_um = std::sqrt(fit.residual_variance) * 1e3;
  if (options.whitener)  // the noise level the covariance rests on: the whitened fit's
    out.sigma_um = std::sqrt(fit.residuals.squaredNorm() /
                             std::max(1.0, static_cast<double>(data.size() - fit.summary.num_free))) * 1e3;
  out.covariance = std::move(fit.covariance);
  out.jacobian = std::move(fit.jacobian);
  for (bool f : fit.free) out.fixed.push_back(!f);
  out.parameters = std::move(fit.estimates);
  out.unobservable = std::move(fit.unobservable);
  out.summary = fit.summary;
  if (!out.converged) out.notes.push_back("the fit did not converge: " + fit.summary.message);
  return out;
}

}  // namespace rotacal
