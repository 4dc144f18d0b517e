// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The diagnosis catalogue of ../shared/spec/effects.md as exact extensions of the baseline
/// kinematics (machine.hpp). Each `Effect` is one catalogue id with its parameters; an
/// `EffectModel` is a list of them with their parameters stored back to back, so a fit can
/// hand Ceres one parameter block. Every formula here is evaluated on Scalar so Jets flow.
///
/// Composition (one definition, used by simulators, fits and the diagnosis):
///   table:  T(tilt, rot, t) = D(t) * K(tilt) * M_T(tilt') * E_T(tilt) * M_C(rot') * E_C(rot)
///     M_T, M_C   rotations about the actual axis lines (machine.hpp), at the actual angles
///                tilt' = tilt + zero offset + angular positioning - backlash, servo lag
///                and reversal spike terms of the axis' motion (same for rot')
///     E_T, E_C   error motions of each axis in its turning frame (radial, axial, tilt
///                motion harmonics), applied before that axis' rotation (effects.md)
///     K          coning of the tilt axis: rotation k*tilt about X (B machines) or Y (A)
///     D(t)       translations in the machine frame: gravity sag, structural thermal drift
///   tool:   p_tool = xyz + tool offset + squareness + scale terms (commanded xyz)
///   ballbar reading: |p_tool - T q_pivot| + dL + k t
/// Coning as a left rotation about the machine axis was checked against
/// ../shared/data/rtest_bc_oyama.csv (0.31 um residual RMS for 0.3 um noise; applying it in
/// the B turning frame instead leaves 8-14 um).

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/kinematics/chain_stages.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

/// One catalogue entry, e.g. {angular_positioning, 'C', 1} = "angular_positioning_C_h1".
struct Effect {
  EffectKind kind = EffectKind::ballbar_length_offset;
  char axis = 0;     ///< 'A','B','C' (rotary), 'X','Y','Z' (linear); 0 when not applicable
  int harmonic = 0;  ///< n of the *_hn entries, else 0
  /// straightness_DA: the error direction D ('X','Y','Z'; axis holds the moving axis A);
  /// linear_pitch: the ISO 230-1 rotation letter ('B' for E_BX, 'A' for E_AY). Else 0.
  char direction = 0;
  /// In a diagnosis of several sessions (diagnose/multi_session.hpp): the session an
  /// instrument, set-up or time effect belongs to, id() then "session:id". Empty: the
  /// machine's (or a one-session model's). The kinematics do not read it.
  std::string session;

  /// The effects.md id, "session:" before it when `session` is set.
  std::string id() const;
  /// Parse an effects.md id, optionally "session:id"; throws InvalidArgument naming the id if
  /// it is not in the catalogue.
  static Effect parse(const std::string& id);
  int num_params() const;
  /// Parameter names ("dL", "a", "b", ...) and units ("mm", "rad", "mm/s", ...).
  std::vector<std::string> param_names() const;
  std::vector<std::string> param_units() const;
  /// One-sentence physical cause, for reports.
  std::string cause() const;
  /// True if the effect exists on this machine (A effects on an AC table, not on a BC one).
  bool applies_to(MachineType m) const;
  /// True for the effects of the motion itself (backlash, servo lag, reversal spikes): zero
  /// at a static pose.
  bool depends_on_motion() const;
  /// True for the *_hn entries. Each enters axis_stages through channels of the form
  /// q[2j] cos(nR) + q[2j+1] sin(nR), R the commanded angle of its axis (harmonic_angle), so
  /// the derivative of any reading with respect to its parameters at order n is the
  /// derivative with respect to the cos parameters at order 0 times cos(nR) and sin(nR).
  bool is_harmonic() const;
  bool operator==(const Effect& o) const {
    return kind == o.kind && axis == o.axis && harmonic == o.harmonic && direction == o.direction &&
           session == o.session;
  }
};

/// The candidate list for a machine: every catalogue entry that applies to it, with harmonic
/// orders 1..max_harmonic (radial motion from 2), without the touch probe's own entries.
std::vector<Effect> effect_catalogue(MachineType m, int max_harmonic = 4);

/// A set of effects and the layout of their parameters in one flat vector.
struct EffectModel {
  std::vector<Effect> effects;
  /// a_ref of the linear-axis polynomials (straightness_DA, linear_pitch): the mean commanded
  /// xyz over the session (effects.md), mm. Unset, the simulators and fits take the mean of the
  /// session they are given (centred_on); evaluating an unset model takes the machine zero.
  std::optional<Eigen::Vector3d> linear_reference;

  int num_params() const;
  /// Offset of effect i's first parameter in the flat vector. O(i): a loop over every effect
  /// keeps a running offset instead (the evaluators below), else a model of n effects costs
  /// n^2 per sample.
  int offset(std::size_t i) const;
  /// "id.name" for every parameter, in flat order.
  std::vector<std::string> param_labels() const;
};

/// ā of effects.md: the mean commanded xyz (mm) of a session's samples (anything with `.xyz`).
template <typename Sample>
Eigen::Vector3d mean_commanded_xyz(const std::vector<Sample>& samples) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Sample& s : samples) sum += s.xyz;
  return samples.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(samples.size()));
}

/// `fx` with its linear-axis polynomials about the session's mean, unless the caller set a_ref.
template <typename Sample>
EffectModel centred_on(EffectModel fx, const std::vector<Sample>& samples) {
  if (!fx.linear_reference) fx.linear_reference = mean_commanded_xyz(samples);
  return fx;
}

namespace detail {
// Chain index of the machine's rotary axis with this letter, -1 if it has none.
inline int chain_index(MachineType m, char letter) {
  return chain::index_of(MachineChain(m), letter);
}
}  // namespace detail

/// nR of a rotary effect: the argument of its cos and sin in axis_stages, R the commanded
/// angle of its axis (0 on a machine without that axis).
inline double harmonic_angle(MachineType m, const Effect& f, const RotaryAngles<double>& cmd) {
  return chain::harmonic_angle(MachineChain(m), f, cmd);
}

namespace detail {
using chain::AxisStages;
using chain::PointAccumulator;
using chain::PoseAccumulator;

// The stages of chain_stages.hpp for a MachineType and an EffectModel.
template <typename Scalar>
AxisStages<Scalar> axis_stages(MachineType m, const EffectModel& fx, const Scalar* p,
                               const RotaryAngles<double>& cmd, double t,
                               const RotaryMotion& motion) {
  return chain::stages<Scalar>(MachineChain(m), fx.effects.data(),
                               static_cast<int>(fx.effects.size()), p, cmd, t, motion);
}
}  // namespace detail

/// The table's stages (chain::walk_table_stages: the one place that fixes the order of
/// composition, see the file comment) for a MachineType and an EffectModel; table_pose and
/// table_point below are its two accumulators, the ballbar's chain rule
/// (src/ballbar/length_chain.cpp) a third, and tool_position walks the head side the same way.
template <typename Scalar, typename Accumulator>
void walk_table_stages(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                       const Scalar* p, const RotaryAngles<double>& cmd, double t,
                       const RotaryMotion& motion, Accumulator& acc) {
  chain::walk_table_stages(MachineChain(m), e,
                           detail::axis_stages<Scalar>(m, fx, p, cmd, t, motion), acc);
}

/// Pose of the table in the machine frame with location errors and effects, at commanded
/// rotary angles (rad), time t (s) and motion of the axes (at rest if not given). `p` points
/// at EffectModel::num_params() values.
template <typename Scalar>
Pose<Scalar> table_pose(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                        const Scalar* p, const RotaryAngles<double>& cmd, double t,
                        const RotaryMotion& motion = {}) {
  detail::PoseAccumulator<Scalar> acc;
  walk_table_stages(m, e, fx, p, cmd, t, motion, acc);
  return acc.T;
}

/// Machine-frame position of the table point q (same motion as table_pose, applied to one
/// point: several times cheaper inside a fit).
template <typename Scalar>
Vec3<Scalar> table_point(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                         const Scalar* p, const RotaryAngles<double>& cmd, double t,
                         const Vec3<Scalar>& q, const RotaryMotion& motion = {}) {
  detail::PointAccumulator<Scalar> acc{q};
  walk_table_stages(m, e, fx, p, cmd, t, motion, acc);
  return acc.q;
}

/// Actual position of the controlled point for a commanded xyz (mm): the linear-axis
/// effects (squareness, scale, straightness, angular errors seen through the Z arm).
/// `ball_dz`: the height of the ball above the controlled point (a head's tool vector turned by
/// its axes; 0 without head axes): the angular errors act through the ball's height.
template <typename Scalar>
Vec3<Scalar> linear_axes_position(const EffectModel& fx, const Scalar* p,
                                  const Eigen::Vector3d& xyz, const Scalar& ball_dz = Scalar(0)) {
  return chain::linear_axes_position<Scalar>(
      fx.effects.data(), static_cast<int>(fx.effects.size()), p,
      fx.linear_reference.value_or(Eigen::Vector3d::Zero()), xyz, ball_dz);
}

/// Offset of the ball from where it should be on the tool (tool_offset_Z, tool_offset_X/Y),
/// mm: in the machine frame on a machine without head axes, in the spindle frame (it turns
/// with the head) on a machine with head axes, where tool_offset_Z shortens the tool.
template <typename Scalar>
Vec3<Scalar> tool_offset(const EffectModel& fx, const Scalar* p) {
  return chain::tool_offset<Scalar>(fx.effects.data(), static_cast<int>(fx.effects.size()), p);
}

/// Actual position of the ball (machine frame, mm) for a commanded xyz (mm) at commanded
/// rotary angles (rad), time t (s) and motion of the axes (at rest if not given), on a machine with
/// location errors e and effects fx (parameters p): chain::tool_position, with the tool vector
/// of the machine's pivot and tool lengths (X, Y, Z is the ball without head axes).
template <typename Scalar>
Vec3<Scalar> tool_position(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                           const Scalar* p, const Eigen::Vector3d& xyz,
                           const RotaryAngles<double>& cmd, double t,
                           const Scalar& tool_length_error = Scalar(0),
                           const RotaryMotion& motion = {}) {
  const MachineChain c(m);
  const int n = static_cast<int>(fx.effects.size());
  const Eigen::Vector3d a_ref = fx.linear_reference.value_or(Eigen::Vector3d::Zero());
  if (!c.has_head())
    return chain::tool_position<Scalar>(c, e, fx.effects.data(), n, p, a_ref, xyz,
                                        chain::AxisStages<Scalar>{}, Vec3<Scalar>::Zero());
  return chain::tool_position<Scalar>(c, e, fx.effects.data(), n, p, a_ref, xyz,
                                      detail::axis_stages<Scalar>(m, fx, p, cmd, t, motion),
                                      tool_vector<Scalar>(m, tool_length_error));
}

/// The ball on a machine without head axes (the table machines' tool side); kept for the
/// callers that have no rotary angles at hand.
template <typename Scalar>
Vec3<Scalar> tool_position(const EffectModel& fx, const Scalar* p, const Eigen::Vector3d& xyz,
                           double /*t*/) {
  return linear_axes_position<Scalar>(fx, p, xyz) + tool_offset<Scalar>(fx, p);
}

/// Additive error of the ballbar's own reading (mm) at time t.
template <typename Scalar>
Scalar ballbar_reading_error(const EffectModel& fx, const Scalar* p, double t) {
  Scalar out(0);
  for (std::size_t i = 0, off = 0; i < fx.effects.size(); off += fx.effects[i].num_params(), ++i) {
    const Scalar* q = p + off;
    if (fx.effects[i].kind == EffectKind::ballbar_length_offset) out += q[0];
    if (fx.effects[i].kind == EffectKind::ballbar_thermal_drift) out += q[0] * Scalar(t);
  }
  return out;
}

}  // namespace rotacal

// Compiled once per scalar the library uses (extern template declarations).
#include "rotacal/kinematics/effects_instances.hpp"
