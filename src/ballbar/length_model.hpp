// SPDX-License-Identifier: BSD-3-Clause
// The ballbar problem's residual model over arrays (ballbar/problem.hpp: its layout and its one
// residual), shared by identify_joint, monte_carlo, the design and the several-session fit.
#pragma once

#include <algorithm>
#include <type_traits>

#include "rotacal/ballbar/problem.hpp"
#include "rotacal/core/lanes.hpp"

namespace rotacal {

// r_i = L_model,i - L_i (mm), parameters in the ballbar layout (ballbar/problem.hpp), one centre
// pivot (sessions at several pivots are fitted together by multi/identify.hpp).
// The base model (location errors, pivot, and the tool length and ballbar length offsets)
// has an analytic path: the one model's rotations (rotate_point_about_unit_line) composed
// along the machine's axes for the residual, and the chain rule over their derivatives for
// the Jacobian row, checked against the Jets (r and J) in tests/cpp/test_ballbar_identify.cpp.
// Jets of one sample with 12 parameters were about half of a fit's time (perf,
// ballbar_ac_table2.csv). Any other effect takes the templated model (predicted_length) on
// doubles for the residuals, and on a machine without head axes with one pivot the chain rule
// through the effects' stages for the Jacobian (length_chain.hpp), else Jets.
//
// The member functions are defined once, in length_model.cpp: every file that fits a ballbar
// (identification, Monte Carlo, separation design, several-session fit) used to compile the
// whole residual kernel (the Lanes rows and four Jet widths of the templated model) again.
class BallbarLengthModel : public ResidualModel {
 public:
  /// Throws InvalidArgument for an effect that needs the axes' motion when the arrays were
  /// built without it.
  BallbarLengthModel(const BallbarArrays& d, const EffectModel& fx);
  Eigen::Index num_residuals() const override { return d_.size(); }
  int num_parameters() const override { return static_cast<int>(L_.all.size()); }
  const BallbarLayout& layout() const { return L_; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override;
  bool evaluate_subset(const Eigen::VectorXd& x, Eigen::Index stride, Eigen::VectorXd& r,
                       Eigen::MatrixXd* J) const override;
  /// Whether the residuals and Jacobian come from the analytic path (tests compare it with the
  /// Jets).
  bool analytic() const { return analytic_; }
  /// The Jets' residuals and Jacobian, for that comparison.
  void evaluate_jets(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                     Eigen::MatrixXd* J) const;

 private:
  template <typename S>
  struct Chain;
  static constexpr int kMaxColumns = 13;  // 8 location errors, the pivot, 2 offsets at most
  using JacobianLanes = Eigen::Matrix<Lanes, 1, kMaxColumns>;

  static bool analytic_supported(const EffectModel& fx);
  void commanded_sincos();
  static Chain<Lanes> in_lanes(const Chain<double>& c);
  template <typename SampleOf>
  void evaluate_rows(const Chain<double>& chain, Eigen::Index m, SampleOf sample_of,
                     Eigen::Ref<Eigen::VectorXd> r, Eigen::MatrixXd* J) const;
  Chain<double> chain_at(const Eigen::VectorXd& x) const;
  template <bool WithJacobian>
  Lanes analytic_lanes(const Chain<Lanes>& ch, const Eigen::Index (&idx)[Lanes::kSize],
                       JacobianLanes* J) const;
  template <typename T>
  void sample(Eigen::Index i, const T* p, T* out) const;
  void evaluate_chain(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                      Eigen::MatrixXd& J) const;

  const BallbarArrays& d_;
  const EffectModel& fx_;
  BallbarLayout L_;
  bool analytic_;
  bool chain_;  // otherwise the Jacobian by the chain rule (length_chain.hpp) where it applies
  int nt_;      // table axes: chain axes 0 .. nt_ - 1 carry the pivot, the others the tool
  Eigen::Matrix<double, 4, Eigen::Dynamic> cs_;  // commanded_sincos
};

}  // namespace rotacal
