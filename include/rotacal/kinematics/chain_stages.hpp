// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one definition of the machine's motion with its location errors and the catalogue
/// effects (effects.md), written over any chain and any list of effects so that the fits (a
/// MachineType and an EffectModel: machine.hpp, effects.hpp) and the controller's real-time path
/// (a fixed-size model: realtime/model.hpp) call the same templates. Needs Eigen and the
/// standard library only: no allocation, no exceptions, no library to link.
///
/// A `Chain` has `axis(k)` (k = 0, 1 in chain order: table axes from the bed outwards, then head
/// axes) returning an axis with the members of RotaryAxis that move anything (name, direction,
/// point, position_basis, direction_basis, principal, radial1, radial2, on_head),
/// `rot_index()`, `num_table_axes()` and `has_head()`. An effect has `kind`, `axis`,
/// `harmonic` and `direction` (Effect, effects.hpp). Parameters are one flat array, in order.

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>

#include "rotacal/kinematics/rotation.hpp"

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
/// One more than the largest EffectKind (a reader checks a stored kind against it).
constexpr int kEffectKinds = static_cast<int>(EffectKind::probe_lobing) + 1;

/// Number of parameters of an effect of this kind (Effect::num_params).
constexpr int effect_num_params(EffectKind k) {
  switch (k) {
    case EffectKind::radial_motion:
    case EffectKind::tilt_motion:
      return 4;
    case EffectKind::straightness:
      return 3;
    case EffectKind::angular_positioning:
    case EffectKind::axial_motion:
    case EffectKind::thermal_warmup:
    case EffectKind::reversal_spike:
    case EffectKind::probe_lobing:
    case EffectKind::linear_pitch:
      return 2;
    default:
      return 1;
  }
}

/// The effects of the motion itself (backlash, servo lag, reversal spikes): zero at rest.
constexpr bool effect_depends_on_motion(EffectKind k) {
  return k == EffectKind::rotary_backlash || k == EffectKind::servo_lag ||
         k == EffectKind::reversal_spike;
}

/// The eight location errors of one machine, four per axis in chain order (table axes from
/// the bed outwards, then head axes from the linear axes outwards):
///   index 0, 1: position of the first axis' line; 2, 3: orientation of the first axis;
///   index 4, 5: position of the second axis' line; 6, 7: orientation of the second axis.
/// AC-trt: E_Y0A E_Z0A E_B0A E_C0A E_X0C E_Y0C E_A0C E_B0C (Flynn et al., Table 1 order)
/// BC-trt: E_X0B E_Z0B E_A0B E_C0B E_X0C E_Y0C E_A0C E_B0C
/// B-head-C-table: E_X0C E_Y0C E_A0C E_B0C E_X0B E_Z0B E_A0B E_C0B; nutating axes E_U0R...
/// Positions in mm, orientations in rad.
template <typename Scalar>
struct LocationErrors {
  static constexpr int kSize = 8;
  Eigen::Matrix<Scalar, kSize, 1> v = Eigen::Matrix<Scalar, kSize, 1>::Zero();

  LocationErrors() = default;
  explicit LocationErrors(const Eigen::Matrix<Scalar, kSize, 1>& values) : v(values) {}
  /// View of a raw parameter block (e.g. a Ceres parameter pointer).
  static LocationErrors from_ptr(const Scalar* p) {
    return LocationErrors(Eigen::Map<const Eigen::Matrix<Scalar, kSize, 1>>(p));
  }
  template <typename Other>
  LocationErrors<Other> cast() const {
    return LocationErrors<Other>(v.template cast<Other>());
  }
};

/// An axis line: a point it passes through and a (not necessarily unit) direction.
template <typename Scalar>
struct AxisLine {
  Vec3<Scalar> point;
  Vec3<Scalar> direction;
};

/// Rotary axis positions (rad): `tilt` of the tilt axis (A or B), `rot` of the rotary axis
/// (C), whichever side of the chain they are on (MachineDescription::rot_index).
template <typename Scalar>
struct RotaryAngles {
  Scalar tilt = Scalar(0);
  Scalar rot = Scalar(0);
};

/// How the rotary axes move at a sample (issue 16: effects that depend on the direction and
/// speed of motion). `rate`: commanded angular velocity of each axis, rad/s; `direction`: +1 or
/// -1, the sign of the current motion, or of the last one when the axis is at rest (it stays
/// on that side of its lost motion), 0 when no motion is on record; `since_reversal`: time
/// since the axis last reversed its direction, s (infinity when no reversal is on record).
/// The default, at rest with no history, is what a static pose (R-test) or a caller without
/// motion information gets: every motion effect is zero there.
struct RotaryMotion {
  RotaryAngles<double> rate;
  RotaryAngles<double> direction;
  RotaryAngles<double> since_reversal{std::numeric_limits<double>::infinity(),
                                      std::numeric_limits<double>::infinity()};
};

/// thermal_warmup's time factor 1 - exp(-t / tau), tau = 300 s e^q (the table shifts by d times
/// it): the one definition, used by the motion below and by the diagnosis' profile of tau.
template <typename Scalar>
Scalar thermal_warmup_factor(double t, const Scalar& q) {
  using std::exp;
  return Scalar(1) - exp(-Scalar(t) / (Scalar(300) * exp(q)));
}

/// Which rigid stage of chain axis k an accumulator is handed (chain::walk_table_stages).
enum class RigidStage { error_motion, coning };

namespace chain {

// v += B * (a, b) for a 3x2 basis of unit vectors, skipping zero entries (Jets are not free).
template <typename Scalar>
void add_basis(Vec3<Scalar>& v, const Eigen::Matrix<double, 3, 2>& B, const Scalar& a,
               const Scalar& b) {
  for (int i = 0; i < 3; ++i) {
    if (B(i, 0) != 0.0)
      v[i] += B(i, 0) == 1.0 ? a : B(i, 0) == -1.0 ? Scalar(-a) : Scalar(B(i, 0) * a);
    if (B(i, 1) != 0.0)
      v[i] += B(i, 1) == 1.0 ? b : B(i, 1) == -1.0 ? Scalar(-b) : Scalar(B(i, 1) * b);
  }
}

/// Actual line of chain axis k (0, 1) at all rotary axes 0: through p0 + dp along n + dn
/// (formats.md). Table axes in the machine frame, head axes relative to the controlled point.
template <typename Scalar, typename Chain>
AxisLine<Scalar> axis_line(const Chain& c, int k, const LocationErrors<Scalar>& e) {
  const auto& a = c.axis(k);
  AxisLine<Scalar> L{a.point.template cast<Scalar>(), a.direction.template cast<Scalar>()};
  add_basis(L.point, a.position_basis, e.v[4 * k], e.v[4 * k + 1]);
  add_basis(L.direction, a.direction_basis, e.v[4 * k + 2], e.v[4 * k + 3]);
  return L;
}

/// Angle of chain axis k.
template <typename Scalar, typename Chain>
const Scalar& angle(const Chain& c, const RotaryAngles<Scalar>& a, int k) {
  return k == c.rot_index() ? a.rot : a.tilt;
}

/// Chain index of the chain's rotary axis with this letter, -1 if it has none.
template <typename Chain>
int index_of(const Chain& c, char letter) {
  for (int k = 0; k < 2; ++k)
    if (c.axis(k).name == letter) return k;
  return -1;
}

/// nR of a rotary effect: the argument of its cos and sin in stages, R the commanded angle of
/// its axis (0 on a machine without that axis).
template <typename Chain, typename EffectT>
double harmonic_angle(const Chain& c, const EffectT& f, const RotaryAngles<double>& cmd) {
  const int k = index_of(c, f.axis);
  return k < 0 ? 0.0 : f.harmonic * angle(c, cmd, k);
}

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
template <typename Axis>
Eigen::Vector3d coning_axis(const Axis& a) {
  if (a.principal == 0) return Eigen::Vector3d::UnitY();
  if (a.principal == 1) return Eigen::Vector3d::UnitX();
  return a.radial1;
}

/// Nominal ball centre relative to the spindle at all head axes 0 (mm): (0, 0, -length).
/// `length` is pivot length + tool length (+ its error) on a machine with head axes; on a
/// table-table machine the fits pass 0 (X, Y, Z is the ball) and a controller its tool length.
template <typename Scalar>
Vec3<Scalar> tool_vector(const Scalar& length) {
  return Vec3<Scalar>(Scalar(0), Scalar(0), -length);
}

/// Per chain axis: the actual angle and the optional error-motion and coning poses; per side:
/// translation stages. One pass over the effects fills both sides.
template <typename Scalar>
struct AxisStages {
  Scalar angle[2];
  std::optional<Pose<Scalar>> E[2];  // error motion of chain axis k, in its turning frame
  std::optional<Pose<Scalar>> K[2];  // coning of chain axis k, applied after its rotation (in
                                     // the frame of the axis that carries it: effects.md coning)
  std::optional<Vec3<Scalar>> D[2];  // translations of the table side [0] and the head side [1]
};

// One rotary effect's share of the stages (stages below).
template <typename Scalar, typename Axis, typename EffectT>
void add_rotary_effect(AxisStages<Scalar>& st, int k, const Axis& ax, const EffectT& f,
                       const Scalar* q, double R, double nR, const RotaryMotion& motion,
                       int rot_index) {
  using std::cos;
  using std::exp;
  const auto motion_of = [&](const RotaryAngles<double>& a) {
    return k == rot_index ? a.rot : a.tilt;
  };
  const int side = ax.on_head ? 1 : 0;
  const double c = std::cos(nR), s = std::sin(nR);
  switch (f.kind) {
    case EffectKind::rotary_zero_offset:
      st.angle[k] += q[0];
      break;
    case EffectKind::angular_positioning:
      st.angle[k] += q[0] * c + q[1] * s;
      break;
    case EffectKind::rotary_backlash:  // trails by b/2 on the side it last moved from
      st.angle[k] -= Scalar(0.5 * motion_of(motion.direction)) * q[0];
      break;
    case EffectKind::servo_lag:
      st.angle[k] -= Scalar(motion_of(motion.rate)) * q[0];
      break;
    case EffectKind::reversal_spike: {  // sticks after reversing: tau_s = 0.05 s e^q
      const double dt = motion_of(motion.since_reversal);
      // q held within [-6, 6] (tau_s 0.12 ms .. 20 s): a fit that wanders while h is
      // still near 0 would otherwise overflow e^q into a NaN Jacobian.
      const Scalar q1 = q[1] < Scalar(-6) ? Scalar(-6) : q[1] > Scalar(6) ? Scalar(6) : q[1];
      if (std::isfinite(dt) && dt >= 0.0)
        st.angle[k] -= Scalar(motion_of(motion.direction)) * q[0] *
                       exp(-Scalar(dt) / (Scalar(0.05) * exp(q1)));
      break;
    }
    case EffectKind::radial_motion:
    case EffectKind::axial_motion:
    case EffectKind::tilt_motion: {
      if (!st.E[k]) st.E[k].emplace();
      Pose<Scalar>& E = *st.E[k];
      const Vec3<Scalar> d1 = ax.radial1.template cast<Scalar>(),
                         d2 = ax.radial2.template cast<Scalar>();
      if (f.kind == EffectKind::radial_motion) {
        E.t += d1 * (q[0] * c + q[1] * s) + d2 * (q[2] * c + q[3] * s);
      } else if (f.kind == EffectKind::axial_motion) {
        E.t += ax.direction.template cast<Scalar>() * (q[0] * c + q[1] * s);
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
          rotation_about_axis<Scalar>(coning_axis(ax).template cast<Scalar>(), q[0] * Scalar(R)) *
          st.K[k]->R;
      break;
    default:
      break;
  }
}

/// The stages of the motion at commanded angles `cmd` (rad), time t (s) and `motion`, for the
/// n effects fx with their parameters p back to back.
template <typename Scalar, typename Chain, typename EffectT>
AxisStages<Scalar> stages(const Chain& c, const EffectT* fx, int n, const Scalar* p,
                          const RotaryAngles<double>& cmd, double t, const RotaryMotion& motion) {
  AxisStages<Scalar> st;
  for (int k = 0; k < 2; ++k) st.angle[k] = Scalar(angle(c, cmd, k));
  for (int i = 0, off = 0; i < n; off += effect_num_params(fx[i].kind), ++i) {
    const EffectT& f = fx[i];
    const Scalar* q = p + off;
    const bool rotary = f.kind == EffectKind::rotary_zero_offset ||
                        f.kind == EffectKind::angular_positioning ||
                        f.kind == EffectKind::radial_motion || f.kind == EffectKind::axial_motion ||
                        f.kind == EffectKind::tilt_motion || f.kind == EffectKind::gravity_sag ||
                        f.kind == EffectKind::coning || effect_depends_on_motion(f.kind);
    if (rotary) {
      const int k = index_of(c, f.axis);
      if (k < 0) continue;  // validated by the callers (Effect::applies_to)
      add_rotary_effect(st, k, c.axis(k), f, q, angle(c, cmd, k), harmonic_angle(c, f, cmd), motion,
                        c.rot_index());
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

/// Walks the stages of the table's motion from the innermost (the workpiece-side axis' error
/// motion) to the outermost (machine-frame translations), handing each to `acc`:
/// `acc.rigid(Pose, k, RigidStage)` for error motions and coning of chain axis k,
/// `acc.about_line(AxisLine, angle, k)` for its rotation, `acc.translate(Vec3)` for drift and
/// sag. Identity stages are skipped. This is the one place that fixes the order of composition
/// (effects.hpp's file comment).
template <typename Scalar, typename Chain, typename Accumulator>
void walk_table_stages(const Chain& c, const LocationErrors<Scalar>& e,
                       const AxisStages<Scalar>& st, Accumulator& acc) {
  for (int k = c.num_table_axes() - 1; k >= 0; --k) {
    if (st.E[k]) acc.rigid(*st.E[k], k, RigidStage::error_motion);
    acc.about_line(axis_line(c, k, e), st.angle[k], k);
    if (st.K[k]) acc.rigid(*st.K[k], k, RigidStage::coning);
  }
  if (st.D[0]) acc.translate(*st.D[0]);
}

/// The head side the same way, from the spindle (the outermost head axis) to the controlled
/// point: K_H1 Rot(H1) E_H1 * K_H2 Rot(H2) E_H2, then the head's translations.
template <typename Scalar, typename Chain, typename Accumulator>
void walk_head_stages(const Chain& c, const LocationErrors<Scalar>& e, const AxisStages<Scalar>& st,
                      Accumulator& acc) {
  const int nt = c.num_table_axes();
  for (int k = 1; k >= nt; --k) {
    if (st.E[k]) acc.rigid(*st.E[k], k, RigidStage::error_motion);
    acc.about_line(axis_line(c, k, e), st.angle[k], k);
    if (st.K[k]) acc.rigid(*st.K[k], k, RigidStage::coning);
  }
  if (st.D[1]) acc.translate(*st.D[1]);
}

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

/// Actual position of the controlled point for a commanded xyz (mm): the linear-axis
/// effects (squareness, scale, straightness, angular errors seen through the Z arm) about
/// a_ref (mm). `ball_dz`: the height of the ball above the controlled point (a head's tool
/// vector turned by its axes; 0 without head axes): the angular errors act through it.
template <typename Scalar, typename EffectT>
Vec3<Scalar> linear_axes_position(const EffectT* fx, int n, const Scalar* p,
                                  const Eigen::Vector3d& a_ref, const Eigen::Vector3d& xyz,
                                  const Scalar& ball_dz) {
  Vec3<Scalar> out = xyz.cast<Scalar>();
  for (int i = 0, off = 0; i < n; off += effect_num_params(fx[i].kind), ++i) {
    const EffectT& f = fx[i];
    const Scalar* q = p + off;
    const int k = axis_index(f.axis);
    switch (f.kind) {
      case EffectKind::linear_squareness:  // XY: x += s y; YZ: y += s z; ZX: z += s x
        out[k] += q[0] * Scalar(xyz[(k + 1) % 3]);
        break;
      case EffectKind::linear_scale:
        out[k] += q[0] * Scalar(xyz[k]);
        break;
      case EffectKind::straightness: {  // E_DA, u = (a - a_ref) / 100 mm
        const double u = (xyz[k] - a_ref[k]) / 100.0;
        out[axis_index(f.direction)] +=
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
template <typename Scalar, typename EffectT>
Vec3<Scalar> tool_offset(const EffectT* fx, int n, const Scalar* p) {
  Vec3<Scalar> out = Vec3<Scalar>::Zero();
  for (int i = 0, off = 0; i < n; off += effect_num_params(fx[i].kind), ++i) {
    if (fx[i].kind == EffectKind::tool_offset_Z) out.z() += p[off];
    if (fx[i].kind == EffectKind::tool_offset) out[axis_index(fx[i].axis)] += p[off];
  }
  return out;
}

/// Actual position of the ball (machine frame, mm) for a commanded xyz (mm), the stages `st`
/// of the commanded angles and the tool vector `tv` (tool_vector): without head axes
/// xyz' + tool offset + tv; with head axes
///   ball = xyz' + D_h + K_H1 Rot(H1) E_H1 * K_H2 Rot(H2) E_H2 * (tv + tool offset),
/// a coning K after its own axis' rotation, in the frame of the axis that carries it (on a
/// head-head machine the C head turns the A axis' coning with it). xyz' is the controlled
/// point with the linear-axis effects (linear_axes_position), whose Abbe arm is the ball's
/// height above the controlled point.
template <typename Scalar, typename Chain, typename EffectT>
Vec3<Scalar> tool_position(const Chain& c, const LocationErrors<Scalar>& e, const EffectT* fx,
                           int n, const Scalar* p, const Eigen::Vector3d& a_ref,
                           const Eigen::Vector3d& xyz, const AxisStages<Scalar>& st,
                           const Vec3<Scalar>& tv) {
  if (!c.has_head())
    return linear_axes_position<Scalar>(fx, n, p, a_ref, xyz, Scalar(0)) +
           tool_offset<Scalar>(fx, n, p) + tv;
  PointAccumulator<Scalar> acc{tv + tool_offset<Scalar>(fx, n, p)};
  walk_head_stages(c, e, st, acc);
  return linear_axes_position<Scalar>(fx, n, p, a_ref, xyz, acc.q.z()) + acc.q;
}

}  // namespace chain
}  // namespace rotacal
