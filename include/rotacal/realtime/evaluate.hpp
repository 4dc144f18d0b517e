// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Forward and inverse kinematics of a fitted model for a controller's servo thread: the
/// formulas of kinematics/chain_stages.hpp (the ones the fits and simulators use), on a
/// realtime::Model. No allocation, no exceptions, no locks, no I/O; bounded time (the inverse
/// takes a fixed number of steps). Eigen and the standard library only.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

#include "rotacal/kinematics/chain_stages.hpp"
#include "rotacal/realtime/model.hpp"

namespace rotacal {
namespace realtime {

/// Ball (tool tip) in the machine frame and the spindle direction in the machine frame, and the
/// table's pose, for joints q: the parts forward() composes.
struct MachineFramePose {
  Pose<double> table;  ///< table frame -> machine frame
  Eigen::Vector3d tip, direction;
};

/// The location errors at thermal state s: errors + gain (y1, y2).
inline LocationErrors<double> errors_at(const Model& m, const State& s) {
  return LocationErrors<double>(m.errors.v + m.thermal_gain * Eigen::Vector2d(s.y1, s.y2));
}

/// Length of the tool vector (chain::tool_vector): pivot + tool length with head axes.
inline double tool_vector_length(const Model& m, const State& s) {
  return m.has_head() ? m.pivot_length + s.tool_length : s.tool_length;
}

/// The machine-frame parts of forward().
inline MachineFramePose machine_frame_pose(const Model& m, const Joints& q, const State& s) {
  const LocationErrors<double> e = errors_at(m, s);
  const chain::AxisStages<double> st =
      chain::stages<double>(m, m.effects, m.num_effects, m.params, q.angles, s.t, s.motion);
  chain::PoseAccumulator<double> table;
  chain::walk_table_stages(m, e, st, table);
  MachineFramePose out;
  out.table = table.T;
  out.tip =
      chain::tool_position<double>(m, e, m.effects, m.num_effects, m.params, m.linear_reference,
                                   q.xyz, st, chain::tool_vector(tool_vector_length(m, s)));
  out.direction = Eigen::Vector3d::UnitZ();
  if (m.has_head()) {
    chain::PoseAccumulator<double> head;
    chain::walk_head_stages(m, e, st, head);
    out.direction = head.T.R.col(2);
  }
  return out;
}

/// Forward kinematics: the tool tip and direction relative to the workpiece for joints q at
/// state s, with every term of the model.
inline ToolPose forward(const Model& m, const Joints& q, const State& s) {
  const MachineFramePose f = machine_frame_pose(m, q, s);
  ToolPose out;
  out.tip = f.table.R.transpose() * (f.tip - f.table.t);
  out.direction = f.table.R.transpose() * f.direction;
  return out;
}

/// The model's nominal machine: the same chain without location errors, effects or thermal gains.
inline Model nominal_of(const Model& m) {
  Model n;
  for (int k = 0; k < 2; ++k) n.axes[k] = m.axes[k];
  n.table_axes = m.table_axes;
  n.rot = m.rot;
  n.pivot_length = m.pivot_length;
  return n;
}

/// Outcome of inverse(): the joints, and how far their forward() is from the target.
struct InverseResult {
  Joints joints;
  double tip_error = 0;        ///< mm, |forward(joints).tip - target tip|
  double direction_error = 0;  ///< rad (small angle), |forward(joints).direction - target|
};

/// Steps of inverse(). Each multiplies the error by the model's contraction factor, which
/// tests/cpp/test_realtime.cpp requires below 0.1 over the built-in machines' travel away from
/// the singular pose (|tilt| >= 0.02 rad; location errors of 0.05 mm and 0.1 mrad, every
/// catalogue term): five steps take the nominal inverse's error (the model's size, < 1 mm) below
/// 0.1^5 mm = 0.01 um.
constexpr int kInverseSteps = 5;

/// Inverse kinematics. `world` holds the target as a controller's trt kinematics does: the tool
/// tip relative to the workpiece (xyz, mm) and the nominal rotary angles (rad), which fix the
/// target direction as the nominal machine's tool direction at those angles. Returns the
/// joints whose actual tip and direction (forward()) equal the target: kInverseSteps chord
/// Newton steps from the nominal inverse (the Jacobian of the nominal machine at the world
/// angles; a damping of 1e-12 rad^2 keeps the rotary axis where it is at the singular pose).
/// `steps`: fewer for tests of the contraction.
inline InverseResult inverse(const Model& m, const Joints& world, const State& s,
                             int steps = kInverseSteps) {
  const Model nom = nominal_of(m);
  State s0;
  s0.tool_length = s.tool_length;
  // Nominal inverse: the nominal tip at xyz = 0, moved to the target by the table's pose.
  Joints q;
  q.angles = world.angles;
  const MachineFramePose f0 = machine_frame_pose(nom, q, s0);
  q.xyz = f0.table * world.xyz - f0.tip;
  const ToolPose target{world.xyz, f0.table.R.transpose() * f0.direction};
  // Nominal Jacobian of (tip, direction) over (x, y, z, tilt, rot): tip = T^-1 (xyz + ...).
  Eigen::Matrix<double, 6, 5> J = Eigen::Matrix<double, 6, 5>::Zero();
  J.topLeftCorner<3, 3>() = f0.table.R.transpose();
  const double h = 1e-6;  // rad: forward differences, error ~h * 1 mm, far below the chord's
  for (int a = 0; a < 2; ++a) {
    Joints qa = q;
    (a == 0 ? qa.angles.tilt : qa.angles.rot) += h;
    const ToolPose pa = forward(nom, qa, s0), p0 = forward(nom, q, s0);
    J.block<3, 1>(0, 3 + a) = (pa.tip - p0.tip) / h;
    J.block<3, 1>(3, 3 + a) = (pa.direction - p0.direction) / h;
  }
  Eigen::Matrix<double, 5, 5> N = J.transpose() * J;
  N(3, 3) += 1e-12;
  N(4, 4) += 1e-12;
  const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> solver(N);
  Eigen::Matrix<double, 6, 1> r;
  for (int i = 0; i <= steps; ++i) {
    const ToolPose p = forward(m, q, s);
    r.head<3>() = p.tip - target.tip;
    r.tail<3>() = p.direction - target.direction;
    if (i == steps) break;
    const Eigen::Matrix<double, 5, 1> dx = solver.solve(J.transpose() * r);
    q.xyz -= dx.head<3>();
    q.angles.tilt -= dx[3];
    q.angles.rot -= dx[4];
  }
  InverseResult out;
  out.joints = q;
  out.tip_error = r.head<3>().norm();
  out.direction_error = r.tail<3>().norm();
  return out;
}

/// The nominal rotary angles whose nominal tool direction (relative to the workpiece) is
/// `direction`: kInverseSteps chord Newton steps from `start` (the Jacobian of the nominal
/// direction at `start`, damped by 1e-12 rad^2 as in inverse(), so that the rotary axis stays at
/// `start` at the singular pose). The world angles of a controller's forward kinematics.
inline RotaryAngles<double> nominal_angles(const Model& m, const Eigen::Vector3d& direction,
                                           RotaryAngles<double> start, int steps = kInverseSteps) {
  const Model nom = nominal_of(m);
  Joints q;
  q.angles = start;
  const State s0;
  const Eigen::Vector3d d0 = forward(nom, q, s0).direction;
  Eigen::Matrix<double, 3, 2> J;
  const double h = 1e-6;  // rad, as inverse()
  for (int a = 0; a < 2; ++a) {
    Joints qa = q;
    (a == 0 ? qa.angles.tilt : qa.angles.rot) += h;
    J.col(a) = (forward(nom, qa, s0).direction - d0) / h;
  }
  Eigen::Matrix2d N = J.transpose() * J;
  N(0, 0) += 1e-12;
  N(1, 1) += 1e-12;
  const Eigen::LDLT<Eigen::Matrix2d> solver(N);
  Eigen::Vector3d r = d0 - direction;
  for (int i = 0; i < steps; ++i) {
    const Eigen::Vector2d dx = solver.solve(J.transpose() * r);
    q.angles.tilt -= dx[0];
    q.angles.rot -= dx[1];
    r = forward(nom, q, s0).direction - direction;
  }
  return q.angles;
}

/// Forward kinematics as a controller's world coordinates hold it, the exact counterpart of
/// inverse(): the tool tip relative to the workpiece (xyz) and the nominal angles of the actual
/// tool direction, so that inverse(forward_world(q)) is q (to the inverse's bound) and a
/// controller that switches between joint and world coordinates sees no jump.
inline Joints forward_world(const Model& m, const Joints& q, const State& s) {
  const ToolPose p = forward(m, q, s);
  Joints w;
  w.xyz = p.tip;
  w.angles = nominal_angles(m, p.direction, q.angles);
  return w;
}

}  // namespace realtime
}  // namespace rotacal
