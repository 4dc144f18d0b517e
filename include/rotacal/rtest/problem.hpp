// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The R-test problem: the one parameter layout and the one residual model of every R-test fit
/// (the joint identification, its Monte Carlo check, the design, the diagnosis and its
/// uncertainty budget).
///
/// Layout (core/parameter_layout.hpp), in vector order:
///   location_errors  8, location_error_names(machine) order (mm, rad)
///   tool_offset_Z    1 on a machine with head axes (minus the error of pivot_length +
///                    tool_length, along the spindle), else absent
///   map_tilt         tilt-map coefficients of the joint model's smooth basis (identify_joint.hpp)
///   map_rot          rotary-map coefficients
///   zeros            probe zero per set-up, 3 each (x, y, z; items of 3)
///   effects          catalogue effects' parameters (kinematics/effects.hpp order)
/// The table pose is either the joint model's (location errors and the smooth maps, Oyama
/// Eqs. 5-7: rtest_joint_reading) or the machine model's (location errors and catalogue
/// effects: rtest_reading, rtest/model.hpp); a problem has maps or effects, not both.
/// Residual, three per pose: r = d_model + zero_setup - d_measured (mm), Eq. 4.

#include <string>
#include <vector>

#include "rotacal/core/joint_fit.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/model.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// The blocks of an R-test parameter vector.
struct RtestLayout {
  ParameterLayout all;
  ParameterBlock errors, tool, map_tilt, map_rot, zeros, effects;
};

/// How the probe zeros are named: "zero.<setup>.x" (the identification and the diagnosis) or
/// "zero_x#<setup>" (the design's joint information of a session and an added nest).
enum class RtestZeroNames { dotted, numbered };

/// The layout of a problem on machine m with a probe zero for each of `setups`, the maps of
/// `basis` (nullptr: none) and the parameters of fx.
RtestLayout rtest_layout(MachineType m, const std::vector<std::string>& setups,
                         const RtestBasis* basis, const EffectModel& fx,
                         RtestZeroNames zero_names = RtestZeroNames::dotted);

/// The poses of an R-test fit as arrays (structure of arrays), three residual rows each.
struct RtestArrays {
  MachineType machine = MachineType::BC_trt;
  std::vector<std::string> setups;  ///< set-up names, in order of first use (the zero items)
  std::vector<int> setup_of;        ///< set-up index of each pose
  Eigen::Matrix3Xd xyz;             ///< commanded linear axes, mm
  Eigen::Matrix3Xd nest;            ///< the pose's nest, table frame, mm
  Eigen::Matrix3Xd d;               ///< measured displacement, table frame, mm
  std::vector<RotaryAngles<double>> angles;  ///< rad
  std::vector<double> time;                  ///< s
  Eigen::Index size() const { return xyz.cols(); }
};

/// The samples of `session` as arrays. With `need_d`, throws InvalidArgument (the message
/// starting with `who`) for a sample without dx, dy, dz; always for a set-up without a nest.
RtestArrays rtest_arrays(const RtestSession& session, const std::string& who, bool need_d = true);

/// r = d_model + zero - d_measured (mm) of pose i of `d` with the machine model's table pose
/// (location errors, tool_offset_Z, effects; no maps), parameters p in `L`'s order (doubles
/// or Jets).
template <typename T>
Vec3<T> rtest_residual(const RtestLayout& L, const RtestArrays& d, const EffectModel& fx,
                       const T* p, Eigen::Index i) {
  const std::size_t k = static_cast<std::size_t>(i);
  const T* zero = p + L.zeros.item_offset(d.setup_of[k]);
  const Vec3<T> r = rtest_reading<T>(d.machine, LocationErrors<T>::from_ptr(L.errors.ptr(p)), fx,
                                     L.effects.ptr(p), d.xyz.col(i), d.angles[k], d.time[k],
                                     d.nest.col(i), L.tool.empty() ? T(0) : T(-p[L.tool.offset]));
  Vec3<T> out;
  for (int a = 0; a < 3; ++a) out[a] = r[a] + zero[a] - T(d.d(a, i));
  return out;
}

/// The R-test residual model over arrays: the joint model's (basis given: location errors,
/// tool_offset_Z, maps, zeros) or the machine model's (location errors, tool_offset_Z, zeros,
/// effects). The joint model's Jacobian: per pose, Jets of rtest_joint_reading with respect to
/// (e, w_BY, w_CB, tool_offset_Z) (21 directions) chained through the pose's basis values,
/// four times fewer directions than the ~70 coefficients; the machine model's by Jets of
/// rtest_residual. Throws InvalidArgument for a basis and effects together.
class RtestProblem : public ResidualModel {
 public:
  RtestProblem(const RtestArrays& d, const RtestBasis* basis, EffectModel fx,
               RtestZeroNames zero_names = RtestZeroNames::dotted);
  const RtestLayout& layout() const { return L_; }
  const EffectModel& effects() const { return fx_; }
  Eigen::Index num_residuals() const override { return 3 * d_.size(); }
  int num_parameters() const override { return static_cast<int>(L_.all.size()); }
  Eigen::Index num_items() const override { return d_.size(); }
  int rows_per_item() const override { return 3; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override;

 private:
  void evaluate_maps(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                     Eigen::MatrixXd* J) const;
  const RtestArrays& d_;
  EffectModel fx_;  // by value: callers pass a model centred on the session (a temporary)
  RtestLayout L_;
  bool maps_;
  // Basis values, 6 rows per pose (rows 6i..6i+5): w_BY = Lb cb, w_CB = Lc cc.
  Eigen::MatrixXd Lb_, Lc_;
};

}  // namespace rotacal
