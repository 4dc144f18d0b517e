// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one model of a touch (../shared/spec/formats.md, "Touch-probe session"; effects.md,
/// stylus_radius_offset and probe_lobing), templated on Scalar so that the joint fit takes its
/// Jacobian by Jets and the simulator evaluates the same formula in double.
///
/// At a trigger the stylus-tip centre p_tool is at distance (D + d)/2 from the actual sphere
/// centre p_table(q_sphere) (D the sphere's and d the stylus' calibrated diameters). One
/// residual per touch:
///   r = | p_tool(xyz - a n) - p_table(q_sphere) | - ((D + d)/2 + delta)
/// with xyz the latched position (the controlled point on a machine with head axes), n the unit
/// approach direction, delta the stylus_radius_offset and a the probe_lobing shift of the
/// latched position along n:
///   a = (lc cos 3 phi + ls sin 3 phi) sqrt(1 - n_z^2),  phi = atan2(n_y, n_x), n in the
///   spindle's frame (the nominal head rotation's inverse applied to n; the machine frame
///   without head axes).
/// p_tool is affine in xyz with unit slope but for the linear-axis effects (scale,
/// squareness, straightness: slopes ~1e-5), so p_tool(xyz - a n) is taken as p_tool(xyz) - a n:
/// the term dropped is slope x a, ~1e-8 mm for a um of lobing.
/// p_table and p_tool are kinematics/effects.hpp's table_point and tool_position: location
/// errors and every catalogue effect act through them, and nowhere else.

#include <cmath>
#include <vector>

#include "rotacal/kinematics/effects.hpp"

namespace rotacal {

/// The catalogue entries a touch-probe session can carry: effect_catalogue(m, max_harmonic)
/// and the probe's own stylus_radius_offset and probe_lobing.
std::vector<Effect> probe_effect_catalogue(MachineType m, int max_harmonic = 4);

/// The approach direction n (machine frame) in the spindle's frame at the commanded angles:
/// the nominal head rotation's inverse applied to n (n itself without head axes).
inline Eigen::Vector3d spindle_frame_direction(MachineType m, const RotaryAngles<double>& angles,
                                               const Eigen::Vector3d& n) {
  if (!m.has_head()) return n;
  return head_pose<double>(m, LocationErrors<double>(), angles).R.transpose() * n;
}

/// One touch as the model needs it: latched xyz (mm), unit approach direction n in the
/// machine frame and in the spindle's frame, commanded angles (rad), time (s).
struct ProbeTouch {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d n_spindle = Eigen::Vector3d::UnitZ();
  RotaryAngles<double> angles;
  double time = 0.0;
};

/// stylus_radius_offset of the effects (mm; 0 without it).
template <typename Scalar>
Scalar stylus_radius_error(const EffectModel& fx, const Scalar* p) {
  Scalar out(0);
  for (std::size_t i = 0; i < fx.effects.size(); ++i)
    if (fx.effects[i].kind == EffectKind::stylus_radius_offset) out += p[fx.offset(i)];
  return out;
}

/// probe_lobing's shift of the latched position along n (mm), for n in the spindle's frame.
template <typename Scalar>
Scalar lobing_shift(const EffectModel& fx, const Scalar* p, const Eigen::Vector3d& n_spindle) {
  Scalar out(0);
  for (std::size_t i = 0; i < fx.effects.size(); ++i) {
    if (fx.effects[i].kind != EffectKind::probe_lobing) continue;
    const double phi = std::atan2(n_spindle.y(), n_spindle.x());
    const double radial = std::sqrt(std::max(0.0, 1.0 - n_spindle.z() * n_spindle.z()));
    const Scalar* q = p + fx.offset(i);
    out +=
        (q[0] * Scalar(std::cos(3.0 * phi)) + q[1] * Scalar(std::sin(3.0 * phi))) * Scalar(radial);
  }
  return out;
}

/// The stylus-tip centre at the trigger, minus the actual sphere centre, machine frame (mm):
/// p_tool(xyz) - a n - p_table(q_sphere). `tool_length_error` as in kinematics tool_position.
template <typename Scalar>
Vec3<Scalar> touch_offset(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                          const Scalar* fx_params, const Vec3<Scalar>& q_sphere,
                          const ProbeTouch& t, const Scalar& tool_length_error = Scalar(0)) {
  const Vec3<Scalar> centre = table_point<Scalar>(m, e, fx, fx_params, t.angles, t.time, q_sphere);
  const Vec3<Scalar> tip =
      tool_position<Scalar>(m, e, fx, fx_params, t.xyz, t.angles, t.time, tool_length_error);
  return tip - t.n.cast<Scalar>() * lobing_shift<Scalar>(fx, fx_params, t.n_spindle) - centre;
}

/// The touch residual of the file comment (mm): |touch_offset| - (trigger_radius + delta).
template <typename Scalar>
Scalar touch_residual(MachineType m, const LocationErrors<Scalar>& e, const EffectModel& fx,
                      const Scalar* fx_params, const Vec3<Scalar>& q_sphere, const ProbeTouch& t,
                      double trigger_radius, const Scalar& tool_length_error = Scalar(0)) {
  using std::sqrt;
  const Vec3<Scalar> d = touch_offset<Scalar>(m, e, fx, fx_params, q_sphere, t, tool_length_error);
  return sqrt(d.squaredNorm()) -
         (Scalar(trigger_radius) + stylus_radius_error<Scalar>(fx, fx_params));
}

}  // namespace rotacal
