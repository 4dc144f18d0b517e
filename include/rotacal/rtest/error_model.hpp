// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Position-dependent geometric errors of a B/C tilting-rotary table (Oyama & Ibaraki, Sec. 2.3):
/// the exact HTM model of Eqs. 4-7 (built from D_x..D_c of Eq. 1), its small-angle form
/// (Eqs. 8-9), and the exact mapping between constant Oyama errors and the ISO 230-7 location
/// errors of machine.hpp.
///
/// Order of a 6-vector of axis errors (translation first, then rotation), used everywhere here:
///   w = (dx, dy, dz, alpha, beta, gamma)   [mm, mm, mm, rad, rad, rad]
/// w_BY: errors of the B axis, in the machine frame in front of D_b(B) (Eq. 6);
/// w_CB: errors of the C axis relative to the B-axis frame (Eq. 7).
///
/// Sign convention. The R-test measures the sphere centre in the table ("workpiece") frame:
///   [^w p; 1] = (^r T_w)^-1 ^r T~_w [^w p*; 1]              (Eq. 4)
/// and rotacal reports d = ^w p - ^w p*. The small-angle quantities (Delta X .. Delta C) of
/// Eq. 9 are the table's own error motion in the table frame, E = T~^-1 T ~ [I + [dA]x | dX], so
/// d ~ -(dR p* + dX): Eq. 8 as printed omits this minus sign; Sec. 5.1 of the paper restores it
/// ("the table displacement is -^w p"). Tests pin both the exact form and this sign.

#include <Eigen/Core>

#include "rotacal/kinematics/machine.hpp"
#include "rotacal/rtest/model.hpp"

namespace rotacal {

template <typename Scalar>
using AxisErrors = Eigen::Matrix<Scalar, 6, 1>;

/// D_x(dx) D_y(dy) D_z(dz) D_a(alpha) D_b(beta) D_c(gamma) (the error factor of Eqs. 6-7) as a
/// Pose.
template <typename Scalar>
Pose<Scalar> oyama_error_pose(const AxisErrors<Scalar>& w) {
  using std::cos;
  using std::sin;
  Pose<Scalar> P;
  P.t = w.template head<3>();
  // D_a(alpha) D_b(beta) D_c(gamma) of Eq. 1 multiplied out: on the joint fit's Jets the three
  // Rodrigues rotations and their two products took about half of the R-test Jacobian's time.
  const Scalar ca = cos(w[3]), sa = sin(w[3]), cb = cos(w[4]), sb = sin(w[4]), cc = cos(w[5]),
               sc = sin(w[5]);
  P.R << cb * cc, -cb * sc, sb,                                  //
      ca * sc + sa * sb * cc, ca * cc - sa * sb * sc, -sa * cb,  //
      sa * sc - ca * sb * cc, sa * cc + ca * sb * sc, ca * cb;
  return P;
}

/// The 4x4 HTM of the same factor, literally the product of Eq. 1's matrices (for tests).
template <typename Scalar>
Mat4<Scalar> oyama_error_htm(const AxisErrors<Scalar>& w) {
  return D_x<Scalar>(w[0]) * D_y<Scalar>(w[1]) * D_z<Scalar>(w[2]) * D_a<Scalar>(w[3]) *
         D_b<Scalar>(w[4]) * D_c<Scalar>(w[5]);
}

/// Inverse of oyama_error_pose: (dx, dy, dz) = t and X-Y-Z Euler angles of R = Rx Ry Rz.
AxisErrors<double> oyama_errors_of(const Pose<double>& P);

/// Eqs. 5-7: ^r T_w = [E(w_BY) D_b(B)] [E(w_CB) D_c(C)], B and C in rad.
template <typename Scalar>
Pose<Scalar> oyama_table_pose(const AxisErrors<Scalar>& w_BY, const AxisErrors<Scalar>& w_CB,
                              const Scalar& B, const Scalar& C) {
  Pose<Scalar> Ry, Rz;
  Ry.R = rotation_about_axis<Scalar>(Vec3<Scalar>::UnitY(), B);
  Rz.R = rotation_about_axis<Scalar>(Vec3<Scalar>::UnitZ(), C);
  return oyama_error_pose(w_BY) * Ry * oyama_error_pose(w_CB) * Rz;
}

/// Eq. 4: R-test reading d = (^r T_w)^-1 ^r T~_w p* - p* (table frame, mm) for the nest at p*.
template <typename Scalar>
Vec3<Scalar> oyama_displacement(const AxisErrors<Scalar>& w_BY, const AxisErrors<Scalar>& w_CB,
                                const Scalar& B, const Scalar& C, const Vec3<Scalar>& p_star) {
  const AxisErrors<Scalar> zero = AxisErrors<Scalar>::Zero();
  const Vec3<Scalar> p_machine = oyama_table_pose<Scalar>(zero, zero, B, C) * p_star;
  return rtest_displacement<Scalar>(oyama_table_pose(w_BY, w_CB, B, C), p_machine,
                                    Eigen::Vector3d::Zero()) -
         p_star;
}

/// Eq. 9: small-angle table error twist (dX, dY, dZ, dA, dB, dC) in the table frame.
template <typename Scalar>
Eigen::Matrix<Scalar, 6, 1> oyama_small_angle_twist(const AxisErrors<Scalar>& w_BY,
                                                    const AxisErrors<Scalar>& w_CB, const Scalar& B,
                                                    const Scalar& C) {
  using std::cos;
  using std::sin;
  const Scalar cB = cos(B), sB = sin(B), cC = cos(C), sC = sin(C);
  // u = Ry(-B) delta_BY + delta_CB (B-axis frame), then Rz(-C) u; same for the rotations.
  const Scalar ux = w_BY[0] * cB - w_BY[2] * sB + w_CB[0];
  const Scalar uy = w_BY[1] + w_CB[1];
  const Scalar uz = w_BY[0] * sB + w_BY[2] * cB + w_CB[2];
  const Scalar ex = w_BY[3] * cB - w_BY[5] * sB + w_CB[3];
  const Scalar ey = w_BY[4] + w_CB[4];
  const Scalar ez = w_BY[3] * sB + w_BY[5] * cB + w_CB[5];
  Eigen::Matrix<Scalar, 6, 1> t;
  t << uy * sC + ux * cC, uy * cC - ux * sC, uz, ey * sC + ex * cC, ey * cC - ex * sC, ez;
  return t;
}

/// Eq. 8 with the sign of Sec. 5.1: d ~ -(dR p* + dX), first order in the errors.
template <typename Scalar>
Vec3<Scalar> oyama_small_angle_displacement(const AxisErrors<Scalar>& w_BY,
                                            const AxisErrors<Scalar>& w_CB, const Scalar& B,
                                            const Scalar& C, const Vec3<Scalar>& p_star) {
  const Eigen::Matrix<Scalar, 6, 1> t = oyama_small_angle_twist(w_BY, w_CB, B, C);
  const Vec3<Scalar> rot = t.template tail<3>();
  return -(rot.cross(p_star) + t.template head<3>());
}

/// Location errors (machine.hpp) + position-dependent deviations in Oyama form: the model of
/// the joint fit. T = E(w_BY) Rot(B line, B) E(w_CB) Rot(C line, C); with e = 0 this is Eqs. 5-7,
/// with w = 0 it is machine.hpp's table_pose. Only BC-trt.
template <typename Scalar>
Pose<Scalar> rtest_table_pose(const LocationErrors<Scalar>& e, const AxisErrors<Scalar>& w_BY,
                              const AxisErrors<Scalar>& w_CB, const Scalar& B, const Scalar& C) {
  return oyama_error_pose(w_BY) * tilt_axis_motion(MachineType::BC_trt, e, B) *
         oyama_error_pose(w_CB) * c_axis_motion(MachineType::BC_trt, e, C);
}

/// Constant Oyama errors equivalent to a set of location errors (BC-trt):
///   table_pose(e; B, C) = [E(w_BY) D_b(B)] [E(w_CB) D_c(C)] * F    for every B, C (exact),
/// where F is a constant rigid transform of the table frame. For an R-test, F moves each nest by
/// a constant table-frame vector, which the per-set-up probe zero absorbs: that is why constant
/// Oyama errors and location errors describe the same readings. Derivation: with a, c the points
/// of the B and C lines and R0 (R1) the rotation taking +Y (+Z) onto the B (C) direction,
///   Rot(B line, B) = Tr(a) R0 Ry(B) R0^T Tr(-a),  Rot(C line, C) = Tr(c) R1 Rz(C) R1^T Tr(-c),
/// so E(w_BY) = Tr(a) R0, E(w_CB) = Tr(R0^T (c - a)) R0^T R1, F = R1^T Tr(-c).
/// R0 = Rx(atan E_A0B) Rz(asin(E_C0B/|u_B|)), R1 = Rx(atan E_A0C) Ry(asin(E_B0C/|u_C|)).
/// To first order:
///   w_BY = (E_X0B, 0, E_Z0B, E_A0B, 0, E_C0B)
///   w_CB = (E_X0C - E_X0B, E_Y0C, -E_Z0B, E_A0C - E_A0B, E_B0C, -E_C0B)
/// dy_BY + dy_CB, beta_BY + beta_CB, dz_CB and gamma_CB of constant errors have no location
/// counterpart: the first two only occur as sums, the last two are absorbed by the probe zeros.
struct OyamaConstantErrors {
  AxisErrors<double> w_BY = AxisErrors<double>::Zero();
  AxisErrors<double> w_CB = AxisErrors<double>::Zero();
  Pose<double> F;  ///< constant table-frame transform (see above)
};
OyamaConstantErrors oyama_from_location(const LocationErrors<double>& e);
/// The first-order mapping above (for reports and for tests of the exact one).
OyamaConstantErrors oyama_from_location_first_order(const LocationErrors<double>& e);

/// Names "dx_BY" ... "gamma_CB" of component k (0..5) of an axis ("BY" or "CB").
std::string oyama_error_name(int k, const std::string& axis);
/// "mm" for k < 3, "rad" otherwise.
inline const char* oyama_error_unit(int k) { return k < 3 ? "mm" : "rad"; }

}  // namespace rotacal
