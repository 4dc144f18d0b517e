// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Simulated ballbar readings of the ISO 230-4 circular tests (circular/plan.hpp) on a machine
/// whose linear axes have the classic errors, with the instrument's coloured noise.
///
/// Actual position of linear axis i (X, Y, Z; a_i its commanded position, theta the commanded
/// path angle, omega = d theta / dt, s_i = sign of the axis' velocity):
///  - servo: a first-order position loop with time constant tau_i = 1 / Kv_i, in its steady
///    state on the circle: the in-plane axis follows R cos(theta - phi_i) with amplitude
///    R / sqrt(1 + omega^2 tau_i^2) and phase lag atan(omega tau_i) (phi_u = 0, phi_v = 90 deg);
///    unequal tau of the two axes makes the circle an ellipse at 45 deg whose tilt changes sign
///    with the direction;
///  - backlash (lost motion) b_i: the axis trails by b_i / 2 in its direction of travel;
///  - reversal spike h_i, tau_s_i: after the axis reverses (at its actual, lagged reversal) it
///    sticks: it stays behind by h_i exp(-dt / tau_s_i) in its new direction;
///  - squareness: x += s_XY y, y += s_YZ z, z += s_ZX x (linear_squareness of the rotary
///    catalogue, same sign);
///  - scale: a_i += k_i a_i (about the machine zero);
///  - straightness (ISO 230-1 E_DA): a_D += c2_DA ((a_A - centre_A) / 100 mm)^2, order 2
///    about the test centre;
///  - cyclic error of the screw: a_i += c_i cos(2 pi a_i / p_i) + d_i sin(2 pi a_i / p_i).
/// Reading = |actual ball - actual pivot| + bar length error + AR(1) noise (per run, at the
/// sample rate: rho per reading, marginal sigma), the actual pivot being the nominal centre
/// plus a centring error.

#include <Eigen/Core>
#include <cstdint>

#include "rotacal/circular/plan.hpp"
#include "rotacal/circular/timeline.hpp"

namespace rotacal {

/// Errors of the three linear axes. Index 0, 1, 2 = X, Y, Z (squareness: XY, YZ, ZX).
/// Units: mm, rad, s (as the effects catalogue).
struct LinearAxisErrors {
  Eigen::Vector3d squareness = Eigen::Vector3d::Zero();  ///< s_XY, s_YZ, s_ZX, rad
  Eigen::Vector3d scale = Eigen::Vector3d::Zero();       ///< k_X, k_Y, k_Z, mm/mm
  /// c2_DA at row D, column A (mm at 100 mm from the centre); the diagonal must be 0.
  Eigen::Matrix3d straightness = Eigen::Matrix3d::Zero();
  Eigen::Vector3d backlash = Eigen::Vector3d::Zero();             ///< b_i, mm
  Eigen::Vector3d spike = Eigen::Vector3d::Zero();                ///< h_i, mm
  Eigen::Vector3d spike_tau = Eigen::Vector3d::Constant(0.015);   ///< tau_s_i, s
  Eigen::Vector3d servo_tau = Eigen::Vector3d::Zero();            ///< tau_i = 1 / Kv_i, s
  Eigen::Vector3d cyclic_cos = Eigen::Vector3d::Zero();           ///< c_i, mm
  Eigen::Vector3d cyclic_sin = Eigen::Vector3d::Zero();           ///< d_i, mm
  Eigen::Vector3d screw_pitch = Eigen::Vector3d::Constant(10.0);  ///< p_i, mm
};

struct CircularSimulationOptions {
  LinearAxisErrors errors;
  Eigen::Vector3d centring_error = Eigen::Vector3d::Zero();  ///< actual - nominal pivot, mm
  double length_error = 0.0;  ///< bar reading offset (calibration of L0), mm
  double noise_um = 0.3;      ///< marginal 1-sigma of the reading noise, um
  double noise_rho = 0.9;     ///< AR(1) correlation between successive readings, [0, 1)
  std::uint64_t seed = 1;
};

/// The session the ballbar records (circular_commanded_session with simulated lengths;
/// noise_um metadata set to the marginal sigma). Throws InvalidArgument naming the field for
/// non-finite errors, a non-zero straightness diagonal, a non-positive pitch or spike time
/// constant, a negative servo time constant, noise outside [0, 1000] um or rho outside [0, 1).
BallbarSession simulate_circular(const CircularPlanResult& plan,
                                 const CircularSimulationOptions& options);

/// The checks simulate_circular makes of its options (InvalidArgument naming the field).
void check_circular_simulation(const CircularSimulationOptions& options);

/// The bar between the actual pivot and the ball on a machine with `options`' errors.
struct CircularBar {
  CircularBar(const CircularTestPlan& plan, const CircularSimulationOptions& options);
  /// Noise-free reading (mm) with the linear axes at actual positions a (mm, before the
  /// geometric errors): |ball - pivot| + length error.
  double reading(const Eigen::Vector3d& a) const;
  CircularSimulationOptions options;
  Eigen::Vector3d tool;         ///< ball - commanded axes at rotary zero, mm
  Eigen::Vector3d centre_axes;  ///< commanded axes at the circle's centre, mm
  Eigen::Vector3d pivot;        ///< actual pivot (nominal centre + centring error), mm
};

/// Noise-free reading (mm) at program time t of the circular program: on a run (run-in, data
/// arc, overshoot) exactly simulate_circular's reading at that time; elsewhere (moves between
/// runs, dwells, remounts) the axes at the commanded point with the geometric errors only
/// (no servo lag, backlash or spike). What a virtual ballbar plays (hw/virtual_instrument.hpp).
double circular_exact_reading(const CircularTimeline& timeline, const CircularBar& bar, double t);

}  // namespace rotacal
