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

#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

/// Kinds of effect in the catalogue. `axis` of an Effect says which axis it belongs to.
enum class EffectKind {
  ballbar_length_offset,  ///< measured length += dL (mm)
  ballbar_thermal_drift,  ///< measured length += k t (mm/s)
  tool_offset_Z,          ///< tool-side ball += (0, 0, d) (mm)
  rotary_zero_offset,     ///< actual angle = R + eps (rad); axis A, B or C
  angular_positioning,    ///< actual angle = R + a cos nR + b sin nR (rad)
  radial_motion,          ///< E(R) translates perpendicular to R (mm), n >= 2
  axial_motion,           ///< E(R) translates along R (mm)
  tilt_motion,            ///< E(R) turns about the two axes perpendicular to R (rad)
  gravity_sag,            ///< table += (0, 0, -s (1 - cos T)) (mm); axis A or B
  coning,                 ///< extra rotation k*T about X (B) or Y (A) (rad/rad)
  linear_squareness,      ///< axis X: x += s y ("XY"), Y: y += s z ("YZ"), Z: z += s x ("ZX")
  linear_scale,           ///< x += k x (likewise y, z)
  thermal_drift,          ///< table += d t along X, Y or Z (mm/s)
  thermal_warmup,         ///< table += d (1 - exp(-t / tau)) along X, Y or Z; tau = 300 s e^q
  straightness,           ///< E_DA: tool D += c2 u^2 + c3 u^3 + c4 u^4, u = (a - a_ref)/100 mm
  tool_offset,            ///< tool-side ball += d along X or Y (mm)
  linear_pitch,           ///< E_BX / E_AY seen through the Z arm: x += e(x) (z - z_ref),
                          ///< y -= e(y) (z - z_ref), e(a) = e1 u + e2 u^2 (rad)
  // Effects of the motion itself (RotaryMotion): a sweep in one direction at one speed sees
  // each as a constant angle offset, i.e. as the zero offset; both directions and two feeds
  // of a tangential test tell them apart (docs/effects.md).
  rotary_backlash,  ///< actual angle -= b/2 * direction (lost motion b, rad)
  servo_lag,        ///< actual angle -= tau * rate (lag behind the linear axes, s)
  reversal_spike,   ///< actual angle -= direction * h exp(-dt / tau_s) after a reversal;
                    ///< tau_s = 0.05 s e^q (h rad, q 1)
  // The touch probe's own effects (probe/touch_model.hpp evaluates them): effect_catalogue
  // leaves them out, probe_effect_catalogue (probe/touch_model.hpp) adds them.
  stylus_radius_offset,  ///< trigger distance from the sphere centre += d (mm)
  probe_lobing,          ///< latched position += (lc cos 3phi + ls sin 3phi) sqrt(1 - nz^2) n (mm)
};

/// One catalogue entry, e.g. {angular_positioning, 'C', 1} = "angular_positioning_C_h1".
struct Effect {
  EffectKind kind = EffectKind::ballbar_length_offset;
  char axis = 0;     ///< 'A','B','C' (rotary), 'X','Y','Z' (linear); 0 when not applicable
  int harmonic = 0;  ///< n of the *_hn entries, else 0
  /// straightness_DA: the error direction D ('X','Y','Z'; axis holds the moving axis A);
  /// linear_pitch: the ISO 230-1 rotation letter ('B' for E_BX, 'A' for E_AY). Else 0.
  char direction = 0;

  /// The effects.md id.
  std::string id() const;
  /// Parse an effects.md id; throws InvalidArgument naming the id if it is not in the catalogue.
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
    return kind == o.kind && axis == o.axis && harmonic == o.harmonic && direction == o.direction;
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
  for (int k = 0; k < 2; ++k)
    if (m.description().axis(k).name == letter) return k;
  return -1;
}
}  // namespace detail

/// thermal_warmup's time factor 1 - exp(-t / tau), tau = 300 s e^q (the table shifts by d times
/// it): the one definition, used by the motion below and by the diagnosis' profile of tau.
template <typename Scalar>
Scalar thermal_warmup_factor(double t, const Scalar& q) {
  using std::exp;
  return Scalar(1) - exp(-Scalar(t) / (Scalar(300) * exp(q)));
}

/// nR of a rotary effect: the argument of its cos and sin in axis_stages, R the commanded
/// angle of its axis (0 on a machine without that axis).
inline double harmonic_angle(MachineType m, const Effect& f, const RotaryAngles<double>& cmd) {
  const int k = detail::chain_index(m, f.axis);
  return k < 0 ? 0.0 : f.harmonic * chain_angle(m, cmd, k);
}

namespace detail {

template <typename Scalar>
Mat3<Scalar> small_rotation_xyz(const Scalar& ax, const Scalar& ay, const Scalar& az) {
  return rotation_about_axis<Scalar>(Vec3<Scalar>::UnitX(), ax) *
         rotation_about_axis<Scalar>(Vec3<Scalar>::UnitY(), ay) *
         rotation_about_axis<Scalar>(Vec3<Scalar>::UnitZ(), az);
}

// Index of X, Y, Z for a linear axis letter (A, B, C map to their principal axes).
inline int axis_index(char axis) {
  return axis == 'A' || axis == 'X' ? 0 : (axis == 'B' || axis == 'Y') ? 1 : 2;
}

// Axis about which coning turns the tilt axis: Y for an A axis, X for a B axis (formats and
// effects.md), the first radial direction u of any other axis.
inline Eigen::Vector3d coning_axis(const RotaryAxis& a) {
  if (a.principal == 0) return Eigen::Vector3d::UnitY();
  if (a.principal == 1) return Eigen::Vector3d::UnitX();
  return a.radial1;
}

// Per chain axis: the actual angle and the optional error-motion and coning poses; per side:
// translation stages. One pass over the effects fills both sides.
template <typename Scalar>
struct AxisStages {
  Scalar angle[2];
  std::optional<Pose<Scalar>> E[2];  // error motion of chain axis k, in its turning frame
  std::optional<Pose<Scalar>> K[2];  // coning of chain axis k, applied after its rotation (in
                                     // the frame of the axis that carries it: effects.md coning)
  std::optional<Vec3<Scalar>> D[2];  // translations of the table side [0] and the head side [1]
};

template <typename Scalar>
AxisStages<Scalar> axis_stages(MachineType m, const EffectModel& fx, const Scalar* p,
                               const RotaryAngles<double>& cmd, double t,
                               const RotaryMotion& motion) {
  using std::cos;
  using std::exp;
  const MachineDescription& d = m.description();
  AxisStages<Scalar> st;
  for (int k = 0; k < 2; ++k) st.angle[k] = Scalar(chain_angle(m, cmd, k));
  for (std::size_t i = 0, off = 0; i < fx.effects.size(); off += fx.effects[i].num_params(), ++i) {
    const Effect& f = fx.effects[i];
    const Scalar* q = p + off;
    const bool rotary = f.kind == EffectKind::rotary_zero_offset ||
                        f.kind == EffectKind::angular_positioning ||
                        f.kind == EffectKind::radial_motion || f.kind == EffectKind::axial_motion ||
                        f.kind == EffectKind::tilt_motion || f.kind == EffectKind::gravity_sag ||
                        f.kind == EffectKind::coning || f.depends_on_motion();
    if (rotary) {
      const int k = chain_index(m, f.axis);
      if (k < 0) continue;  // validated by the callers (Effect::applies_to)
      const RotaryAxis& ax = d.axis(k);
      const int side = ax.on_head ? 1 : 0;
      const double R = chain_angle(m, cmd, k);  // the commanded angle of the effect's axis
      const double nR = harmonic_angle(m, f, cmd), c = std::cos(nR), s = std::sin(nR);
      switch (f.kind) {
        case EffectKind::rotary_zero_offset:
          st.angle[k] += q[0];
          break;
        case EffectKind::angular_positioning:
          st.angle[k] += q[0] * c + q[1] * s;
          break;
        case EffectKind::rotary_backlash:  // trails by b/2 on the side it last moved from
          st.angle[k] -= Scalar(0.5 * chain_angle(m, motion.direction, k)) * q[0];
          break;
        case EffectKind::servo_lag:
          st.angle[k] -= Scalar(chain_angle(m, motion.rate, k)) * q[0];
          break;
        case EffectKind::reversal_spike: {  // sticks after reversing: tau_s = 0.05 s e^q
          const double dt = chain_angle(m, motion.since_reversal, k);
          // q held within [-6, 6] (tau_s 0.12 ms .. 20 s): a fit that wanders while h is
          // still near 0 would otherwise overflow e^q into a NaN Jacobian.
          const Scalar q1 = q[1] < Scalar(-6) ? Scalar(-6) : q[1] > Scalar(6) ? Scalar(6) : q[1];
          if (std::isfinite(dt) && dt >= 0.0)
            st.angle[k] -= Scalar(chain_angle(m, motion.direction, k)) * q[0] *
                           exp(-Scalar(dt) / (Scalar(0.05) * exp(q1)));
          break;
        }
        case EffectKind::radial_motion:
        case EffectKind::axial_motion:
        case EffectKind::tilt_motion: {
          if (!st.E[k]) st.E[k].emplace();
          Pose<Scalar>& E = *st.E[k];
          const Vec3<Scalar> d1 = ax.radial1.cast<Scalar>(), d2 = ax.radial2.cast<Scalar>();
          if (f.kind == EffectKind::radial_motion) {
            E.t += d1 * (q[0] * c + q[1] * s) + d2 * (q[2] * c + q[3] * s);
          } else if (f.kind == EffectKind::axial_motion) {
            E.t += ax.direction.cast<Scalar>() * (q[0] * c + q[1] * s);
          } else if (ax.principal >= 0) {  // small rotations about the two radial directions
            Vec3<Scalar> w = d1 * (q[0] * c + q[1] * s) + d2 * (q[2] * c + q[3] * s);
            E.R = small_rotation_xyz(w[0], w[1], w[2]) * E.R;
          } else {
            E.R = rotation_about_axis<Scalar>(d1, q[0] * c + q[1] * s) *
                  rotation_about_axis<Scalar>(d2, q[2] * c + q[3] * s) * E.R;
          }
          break;
        }
        case EffectKind::gravity_sag:  // the table (or the head) drops by s (1 - cos angle)
          if (!st.D[side]) st.D[side] = Vec3<Scalar>::Zero();
          st.D[side]->z() -= q[0] * (Scalar(1) - cos(Scalar(R)));
          break;
        case EffectKind::coning:
          if (!st.K[k]) st.K[k].emplace();
          st.K[k]->R =
              rotation_about_axis<Scalar>(coning_axis(ax).cast<Scalar>(), q[0] * Scalar(R)) *
              st.K[k]->R;
          break;
        default:
          break;
      }
      continue;
    }
    switch (f.kind) {
      case EffectKind::thermal_drift:
        if (!st.D[0]) st.D[0] = Vec3<Scalar>::Zero();
        (*st.D[0])[axis_index(f.axis)] += q[0] * Scalar(t);
        break;
      case EffectKind::thermal_warmup:  // tau = 300 s * exp(q1): q1 = 0 is a sensible start
        if (!st.D[0]) st.D[0] = Vec3<Scalar>::Zero();
        (*st.D[0])[axis_index(f.axis)] += q[0] * thermal_warmup_factor(t, q[1]);
        break;
      default:  // tool-side and instrument effects do not move the table
        break;
    }
  }
  return st;
}

}  // namespace detail

/// Which rigid stage of chain axis k an accumulator is handed (walk_table_stages).
enum class RigidStage { error_motion, coning };

/// Walks the stages of the table's motion from the innermost (the workpiece-side axis' error
/// motion) to the outermost (machine-frame translations), handing each to `acc`:
/// `acc.rigid(Pose, k, RigidStage)` for error motions and coning of chain axis k,
/// `acc.about_line(AxisLine, angle, k)` for its rotation, `acc.translate(Vec3)` for drift and
/// sag. Identity stages are skipped. This is the one place that fixes the order of composition
/// (see the file comment); table_pose and table_point below are its two accumulators, the
/// ballbar's chain rule (src/ballbar/length_chain.cpp) a third, and tool_position walks the
/// head side the same way.
template <typename Scalar, typename Accumulator>
void walk_table_stages(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                       const Scalar* p, const RotaryAngles<double>& cmd, double t,
                       const RotaryMotion& motion, Accumulator& acc) {
  const detail::AxisStages<Scalar> st = detail::axis_stages<Scalar>(m, fx, p, cmd, t, motion);
  for (int k = static_cast<int>(m.description().table_axes.size()) - 1; k >= 0; --k) {
    if (st.E[k]) acc.rigid(*st.E[k], k, RigidStage::error_motion);
    acc.about_line(axis_line(m, k, e), st.angle[k], k);
    if (st.K[k]) acc.rigid(*st.K[k], k, RigidStage::coning);
  }
  if (st.D[0]) acc.translate(*st.D[0]);
}

namespace detail {
template <typename Scalar>
struct PoseAccumulator {  // T <- stage * T
  Pose<Scalar> T;
  void rigid(const Pose<Scalar>& P, int, RigidStage) { T = P * T; }
  void about_line(const AxisLine<Scalar>& L, const Scalar& a, int) {
    T = rotation_about_line(L.point, L.direction, a) * T;
  }
  void translate(const Vec3<Scalar>& d) { T.t += d; }
};
template <typename Scalar>
struct PointAccumulator {  // q <- stage(q)
  Vec3<Scalar> q;
  void rigid(const Pose<Scalar>& P, int, RigidStage) { q = P * q; }
  void about_line(const AxisLine<Scalar>& L, const Scalar& a, int) {
    q = rotate_point_about_line(L.point, L.direction, a, q);
  }
  void translate(const Vec3<Scalar>& d) { q += d; }
};
}  // namespace detail

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
  Vec3<Scalar> out = xyz.cast<Scalar>();
  const Eigen::Vector3d a_ref = fx.linear_reference.value_or(Eigen::Vector3d::Zero());
  for (std::size_t i = 0, off = 0; i < fx.effects.size(); off += fx.effects[i].num_params(), ++i) {
    const Effect& f = fx.effects[i];
    const Scalar* q = p + off;
    const int k = detail::axis_index(f.axis);
    switch (f.kind) {
      case EffectKind::linear_squareness:  // XY: x += s y; YZ: y += s z; ZX: z += s x
        out[k] += q[0] * Scalar(xyz[(k + 1) % 3]);
        break;
      case EffectKind::linear_scale:
        out[k] += q[0] * Scalar(xyz[k]);
        break;
      case EffectKind::straightness: {  // E_DA, u = (a - a_ref) / 100 mm
        const double u = (xyz[k] - a_ref[k]) / 100.0;
        out[detail::axis_index(f.direction)] +=
            q[0] * Scalar(u * u) + q[1] * Scalar(u * u * u) + q[2] * Scalar(u * u * u * u);
        break;
      }
      case EffectKind::linear_pitch: {  // a rotation of the carriage, times the Z arm
        const double u = (xyz[k] - a_ref[k]) / 100.0;
        const Scalar arm = Scalar(xyz[2] - a_ref[2]) + ball_dz;
        const Scalar e = q[0] * Scalar(u) + q[1] * Scalar(u * u);
        // E_BX (about Y) moves a point above the guide by +e*arm in X; E_AY (about X) by -e*arm in
        // Y.
        out[k] += (f.direction == 'B' ? arm : Scalar(-arm)) * e;
        break;
      }
      default:
        break;
    }
  }
  return out;
}

/// Offset of the ball from where it should be on the tool (tool_offset_Z, tool_offset_X/Y),
/// mm: in the machine frame on a machine without head axes, in the spindle frame (it turns
/// with the head) on a machine with head axes, where tool_offset_Z shortens the tool.
template <typename Scalar>
Vec3<Scalar> tool_offset(const EffectModel& fx, const Scalar* p) {
  Vec3<Scalar> out = Vec3<Scalar>::Zero();
  for (std::size_t i = 0, off = 0; i < fx.effects.size(); off += fx.effects[i].num_params(), ++i) {
    const Effect& f = fx.effects[i];
    if (f.kind == EffectKind::tool_offset_Z) out.z() += p[off];
    if (f.kind == EffectKind::tool_offset) out[detail::axis_index(f.axis)] += p[off];
  }
  return out;
}

/// Actual position of the ball (machine frame, mm) for a commanded xyz (mm) at commanded
/// rotary angles (rad), time t (s) and motion of the axes (at rest if not given), on a machine with
/// location errors e and effects fx (parameters p). Without head axes: the controlled point with
/// the linear-axis effects and the tool offset. With head axes, the head side is walked like the
/// table side:
///   ball = xyz' + D_h + K_H1 Rot(H1) E_H1 * K_H2 Rot(H2) E_H2 * (tool_vector + tool offset),
/// a coning K after its own axis' rotation, in the frame of the axis that carries it (on a
/// head-head machine the C head turns the A axis' coning with it).
template <typename Scalar>
Vec3<Scalar> tool_position(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                           const Scalar* p, const Eigen::Vector3d& xyz,
                           const RotaryAngles<double>& cmd, double t,
                           const Scalar& tool_length_error = Scalar(0),
                           const RotaryMotion& motion = {}) {
  const MachineDescription& d = m.description();
  if (!d.has_head()) return linear_axes_position<Scalar>(fx, p, xyz) + tool_offset<Scalar>(fx, p);
  const detail::AxisStages<Scalar> st = detail::axis_stages<Scalar>(m, fx, p, cmd, t, motion);
  Vec3<Scalar> v = tool_vector<Scalar>(m, tool_length_error) + tool_offset<Scalar>(fx, p);
  const int nt = static_cast<int>(d.table_axes.size());
  for (int k = 1; k >= nt; --k) {
    if (st.E[k]) v = *st.E[k] * v;
    const AxisLine<Scalar> L = axis_line(m, k, e);
    v = rotate_point_about_line(L.point, L.direction, st.angle[k], v);
    if (st.K[k]) v = *st.K[k] * v;
  }
  if (st.D[1]) v += *st.D[1];
  // The ball's height above the controlled point is the Abbe arm of the angular errors.
  return linear_axes_position<Scalar>(fx, p, xyz, v.z()) + v;
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
