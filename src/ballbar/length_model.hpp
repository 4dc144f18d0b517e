// The ballbar joint fit's residual model and set-up, shared by identify_joint and monte_carlo.
#pragma once

#include <algorithm>
#include <type_traits>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/joint_fit.hpp"

namespace rotacal {

// r_i = L_model,i - L_i (mm). Parameters: 8 location errors, pivot (3), effect parameters.
// Residuals alone come from the one templated model (predicted_length); the Jacobian of the
// base model (location errors, pivot, and the tool length and ballbar length offsets) is
// analytic: the chain rule over rotate_point_about_line_derivatives along the machine's axes,
// checked against the Jets in tests/cpp/test_ballbar_identify.cpp. Jets of one sample with
// 12 parameters were about half of a fit's time (perf, ballbar_ac_table2.csv); any other
// effect takes the Jets.
class BallbarLengthModel : public ResidualModel {
 public:
  BallbarLengthModel(const BallbarArrays& d, const EffectModel& fx)
      : d_(d), fx_(fx), P_(fx.num_params()), analytic_(analytic_supported(fx)) {}
  Eigen::Index num_residuals() const override { return d_.size(); }
  int num_parameters() const override { return 11 + P_; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    if (J && analytic_) {
      for (Eigen::Index i = 0; i < d_.size(); ++i) analytic_row(i, x, r[i], J->row(i));
      return;
    }
    evaluate_with_jets([this](Eigen::Index i, const auto* p, auto* out) { sample(i, p, out); },
                       d_.size(), 1, x, r, J);
  }
  bool evaluate_subset(const Eigen::VectorXd& x, Eigen::Index stride, Eigen::VectorXd& r,
                       Eigen::MatrixXd* J) const override {
    const Eigen::Index m = (d_.size() + stride - 1) / stride;
    r.resize(m);
    if (J) J->resize(m, num_parameters());
    if (J && analytic_) {
      for (Eigen::Index k = 0; k < m; ++k) analytic_row(k * stride, x, r[k], J->row(k));
      return true;
    }
    evaluate_with_jets(
        [this, stride](Eigen::Index i, const auto* p, auto* out) { sample(i * stride, p, out); }, m, 1,
        x, r, J);
    return true;
  }
  /// Whether the Jacobian comes from the analytic path (tests compare it with the Jets).
  bool analytic() const { return analytic_; }
  /// The Jets' Jacobian, for that comparison.
  void evaluate_jets(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r, Eigen::MatrixXd* J) const {
    evaluate_with_jets([this](Eigen::Index i, const auto* p, auto* out) { sample(i, p, out); },
                       d_.size(), 1, x, r, J);
  }

 private:
  static bool analytic_supported(const EffectModel& fx) {
    for (const Effect& f : fx.effects)
      if (f.kind != EffectKind::tool_offset_Z && f.kind != EffectKind::ballbar_length_offset) return false;
    return true;
  }

  // Residual and Jacobian row of sample i by the chain rule (see the class comment).
  template <typename Row>
  void analytic_row(Eigen::Index i, const Eigen::VectorXd& x, double& r, Row J) const {
    const MachineType m = d_.machine;
    const MachineDescription& md = m.description();
    const LocationErrors<double> e(x.head<8>());
    const RotaryAngles<double>& cmd = d_.angles[static_cast<std::size_t>(i)];
    double tool_z = 0.0;
    int tool_z_col = -1, length_col = -1;
    for (std::size_t k = 0; k < fx_.effects.size(); ++k) {
      const int col = 11 + fx_.offset(k);
      if (fx_.effects[k].kind == EffectKind::tool_offset_Z) tool_z += x[col], tool_z_col = col;
      else length_col = col;
    }
    const int nt = static_cast<int>(md.table_axes.size());
    LineRotationDerivatives D[2];
    // Table side: the pivot through the table axes, innermost first.
    Eigen::Vector3d P = x.segment<3>(8);
    for (int k = nt - 1; k >= 0; --k) {
      const AxisLine<double> L = axis_line(m, k, e);
      D[k] = rotate_point_about_line_derivatives(L.point, L.direction, chain_angle(m, cmd, k), P);
      P = D[k].f;
    }
    // Tool side: the tool vector through the head axes, innermost first.
    Eigen::Vector3d v = tool_vector<double>(m, 0.0) + Eigen::Vector3d(0.0, 0.0, tool_z);
    for (int k = 1; k >= nt; --k) {
      const AxisLine<double> L = axis_line(m, k, e);
      D[k] = rotate_point_about_line_derivatives(L.point, L.direction, chain_angle(m, cmd, k), v);
      v = D[k].f;
    }
    const Eigen::Vector3d b = d_.xyz.col(i) + v;
    const double length = (b - P).norm();
    const Eigen::Vector3d u = (b - P) / length;
    // The residual from the same chain: the ball points above are the one model's rotations
    // composed as predicted_length composes them (the Jets test checks r as well as J). Taking
    // it from sample() instead evaluated every rotation twice (~0.3 ms of a 1.3 ms fit).
    r = length + (length_col >= 0 ? x[length_col] : 0.0) - d_.length[i];
    J.setZero();
    // dL/d(line k) = +-u^T (outer rotations) dD_k; the table side enters with a minus.
    Eigen::RowVector3d w = -u.transpose();
    for (int k = 0; k < nt; ++k) {
      const RotaryAxis& a = md.axis(k);
      J.template segment<2>(4 * k) = D[k].times_point(w) * a.position_basis;
      J.template segment<2>(4 * k + 2) = D[k].times_direction(w) * a.direction_basis;
      w = D[k].times_q(w);
    }
    J.template segment<3>(8) = w;  // d/dpivot
    w = u.transpose();
    for (int k = nt; k < 2; ++k) {
      const RotaryAxis& a = md.axis(k);
      J.template segment<2>(4 * k) = D[k].times_point(w) * a.position_basis;
      J.template segment<2>(4 * k + 2) = D[k].times_direction(w) * a.direction_basis;
      w = D[k].times_q(w);
    }
    if (tool_z_col >= 0) J[tool_z_col] = w.z();
    if (length_col >= 0) J[length_col] = 1.0;
  }

 private:
  // L_model - L_measured of sample i, on double or Jets.
  template <typename T>
  void sample(Eigen::Index i, const T* p, T* out) const {
    const Vec3<T> pivot(p[8], p[9], p[10]);
    const Eigen::Vector3d xyz = d_.xyz.col(i);
    out[0] = predicted_length<T>(d_.machine, LocationErrors<T>::from_ptr(p), pivot, fx_,
                                 P_ > 0 ? p + 11 : nullptr, xyz, d_.angles[static_cast<std::size_t>(i)],
                                 d_.time[i], d_.motion[static_cast<std::size_t>(i)]) -
             T(d_.length[i]);
  }

  const BallbarArrays& d_;
  const EffectModel& fx_;
  int P_;
  bool analytic_;
};


/// The unknowns (names, units, start values), effects and solver settings of a ballbar joint
/// fit. Throws InvalidArgument for an effect that does not exist on the machine or fewer
/// samples than unknowns.
struct BallbarFitSetup {
  EffectModel effects;
  std::vector<FitParameter> parameters;
  JointFitSettings settings;
};

inline BallbarFitSetup ballbar_fit_setup(const BallbarArrays& data, const JointFitOptions& options) {
  BallbarFitSetup out;
  EffectModel& fx = out.effects;
  fx = options.effects;
  if (options.fit_length_offset)
    fx.effects.insert(fx.effects.begin(), Effect::parse("ballbar_length_offset"));
  // On a machine with head axes the ball's distance from the controlled point,
  // pivot_length + tool_length, is a location parameter of the head (formats.md): its error
  // is fitted as tool_offset_Z, which there acts along the spindle (kinematics/effects.hpp).
  const Effect tool_z = Effect::parse("tool_offset_Z");
  if (data.machine.has_head() &&
      std::find(fx.effects.begin(), fx.effects.end(), tool_z) == fx.effects.end())
    fx.effects.insert(fx.effects.begin(), tool_z);
  for (const Effect& f : fx.effects)
    if (!f.applies_to(data.machine))
      throw InvalidArgument("effect " + f.id() + " does not exist on a " + to_string(data.machine));
  const int n_par = 8 + 3 + fx.num_params();
  if (static_cast<int>(data.size()) < n_par)
    throw InvalidArgument("identify_joint: " + std::to_string(data.size()) +
                          " samples cannot determine " + std::to_string(n_par) + " unknowns");
  // Names, units and start values of the unknowns, in Jacobian column order: zero errors and
  // the nominal pivot.
  std::vector<FitParameter>& params = out.parameters;
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
  out.settings.max_iterations = options.max_iterations;
  out.settings.observability_min_chi2 = options.observability_min_chi2;
  // sigma scales chi-square (observability); the covariance uses the residual variance.
  out.settings.sigma = data.noise_um.value_or(1.0) * 1e-3;
  out.settings.whitener = options.whitener;
  return out;
}

}  // namespace rotacal
