// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The touch-probe problem: its one parameter layout and its one residual model
/// (probe/touch_model.hpp), used by the identification, the Monte Carlo bench and the
/// diagnosis alike.
///
/// Parameters in named blocks (core/parameter_layout.hpp), in vector order:
///   location_errors  8, location_error_names(machine) order (mm, rad)
///   tool_length      tool_offset_Z on a machine with head axes (minus the error of
///                    pivot_length + tool_length, as the R-test fit has it), mm; absent without
///   sphere           the actual sphere centre (table frame, mm: a set-up error, identified like
///                    the ballbar's pivot), sphere.x, sphere.y, sphere.z
///   effects          the parameters of any catalogue effects fitted along (kinematics/effects.hpp)
/// The calibrated radius (D + d)/2 is taken as given, as the controller cycles take it; a wrong
/// one is the diagnosis' stylus_radius_offset. No code here indexes the vector otherwise.

#include <string>
#include <vector>

#include "rotacal/core/joint_fit.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "rotacal/probe/touch_model.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

/// The blocks of a probe parameter vector.
struct ProbeParameterLayout {
  ParameterLayout all;
  ParameterBlock errors;       ///< "location_errors"
  ParameterBlock tool_length;  ///< "tool_length": tool_offset_Z with head axes (size 0 without)
  ParameterBlock sphere;       ///< "sphere": actual sphere centre, table frame, mm
  ParameterBlock effects;      ///< "effects"

  /// The blocks in this order for machine m and effects fx.
  static ProbeParameterLayout make(MachineType m, const EffectModel& fx);
  Eigen::Index size() const { return all.size(); }
};

/// The probe problem of one session with a set of effects: the residual of every touch
/// (touch_residual, mm) and its Jacobian by Jets, over the layout's parameter vector.
class ProbeProblem : public ResidualModel {
 public:
  /// The effects' linear-axis polynomials are about the session's mean latched xyz unless
  /// `effects` fixes a_ref. Throws InvalidArgument for an effect that does not exist on the
  /// session's machine or a session without touches.
  ProbeProblem(const ProbeSession& session, const EffectModel& effects = {});

  const ProbeParameterLayout& layout() const { return layout_; }
  const EffectModel& effects() const { return fx_; }
  MachineType machine() const { return machine_; }
  /// Named parameters in layout order, each starting at zero but the sphere (at the session's
  /// nominal centre) and with its unit; catalogue effects yield to the baseline
  /// (core/yield_convention.hpp).
  std::vector<FitParameter> parameters() const;
  /// Touch residuals at x (mm), with the layout's parameter vector.
  Eigen::VectorXd residuals(const Eigen::VectorXd& x) const;

  Eigen::Index num_residuals() const override { return static_cast<Eigen::Index>(touches_.size()); }
  int num_parameters() const override { return static_cast<int>(layout_.size()); }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override;

  /// Noise streams of the residuals: one group (the session), touches in time order.
  const std::vector<std::string>& groups() const { return groups_; }
  const std::vector<double>& times() const { return times_; }

 private:
  MachineType machine_;
  EffectModel fx_;
  ProbeParameterLayout layout_;
  Eigen::Vector3d sphere_nominal_;
  double radius_ = 0.0;
  std::vector<ProbeTouch> touches_;
  std::vector<std::string> groups_;
  std::vector<double> times_;
};

/// The touches of a session as the model needs them (angles in rad, n in the spindle frame).
std::vector<ProbeTouch> probe_touches(const ProbeSession& session);

}  // namespace rotacal
