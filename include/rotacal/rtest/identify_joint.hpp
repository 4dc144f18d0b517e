// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Joint identification of an R-test session on any machine: one least-squares problem
/// (core/joint_fit.hpp) for the 8 location errors, on a machine with head axes the error of
/// pivot_length + tool_length (tool_offset_Z), the position-dependent errors of both rotary
/// axes in a smooth basis, and an unknown probe zero per set-up, with Jacobians by Jets of the
/// reading. The model (rtest_joint_reading below; on BC-trt error_model.hpp's rtest_table_pose):
///   T = prod over table axes k of E(w_k) Rot(line k, angle k)       (identity without table axes)
///   H = prod over head axes k of E(w_k) Rot(line k, angle k)        (identity without head axes)
///   d = T^-1 (xyz + H t) - q_nest + zero_setup,  t = (0, 0, -(pivot + tool length) +
///   tool_offset_Z)
/// w_k is the tilt axis' map w_BY(B) on the tilt axis and the rotary axis' map w_CB(B, C) on the
/// rotary axis, whichever side of the chain they are on (B = tilt, C = rotary angle; on BC-trt
/// T(B, C) = E(w_BY(B)) Rot(B line, B) E(w_CB(B, C)) Rot(C line, C), Oyama Eqs. 5-7).
/// w_BY, w_CB are the deviations beyond the rigid axis lines (Oyama's errors with the location
/// errors taken out). Basis, with b = B / 90 deg:
///   w_BY translations (dx, dy, dz): even powers b^2, b^4, ... <= b_degree
///   w_BY rotations (alpha, beta, gamma): odd powers b, b^3, ... <= b_degree
///   w_CB component k: sum_{n=1..K} sum_{m=0..M} b^m (a cos nC + s sin nC)
/// Why the parities: a location error of the B axis moves (dx, dz) and (alpha, gamma) in pairs
/// with the signature (1 - cos B, sin B), one even and one odd function; a map with only one
/// parity per pair cannot imitate it, so location errors and map stay separable. Gravity sag
/// (even in B) and coning (odd, Oyama Sec. 5.3) are inside the basis; odd translations and even
/// rotations of the B axis beyond its location errors are outside it (a stated limit). The C map
/// has no constant term (that is the B map's and the location errors' job), and its first
/// harmonic of (dx, dy) and of (alpha, beta) at b^0 turns backwards only: a translation or tilt
/// that turns forwards with C is constant in the table frame, which the probe zeros absorb (on
/// a head it is a constant offset of the sphere from the C line: the C line's position).
/// Head axes: the sphere is one point, so a head map's rotations are seen only as a movement of
/// the sphere, which one tool length cannot tell from the map's translations and the head's
/// direction errors; the fit names such combinations (core observability) and says that a
/// second tool length separates them (the rotations' effect scales with it, a translation's
/// does not).

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/identification.hpp"
#include "rotacal/core/noise_handling.hpp"
#include "rotacal/core/whitener.hpp"
#include "rotacal/rtest/error_model.hpp"
#include "rotacal/rtest/model.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// Number of the model's non-map parameters: the 8 location errors, and on a machine with head
/// axes tool_offset_Z (minus the error of pivot_length + tool_length, along the spindle).
inline int rtest_num_location_parameters(MachineType m) { return m.has_head() ? 9 : 8; }

/// Shape of the smooth basis of the position-dependent errors. "B" and "C" here are the tilt
/// and the rotary axis of any machine (BC-trt's names, Oyama's paper); b = tilt / 90 deg.
struct RtestBasis {
  int b_degree = 6;     ///< highest power of b = tilt/90deg in the tilt map (0: no tilt map)
  int c_harmonics = 2;  ///< harmonics 1..K of the rotary angle in its map (0: no rotary map)
  int c_b_degree = 1;   ///< rotary-map coefficients are polynomials of degree 0..M in b
  /// Include gamma_CB (angular positioning of C) in the C map. Off by default, as Oyama Sec. 4.2
  /// assumes: two nests see 5 of the table's 6 degrees of freedom per pose, and gamma_CB's first
  /// harmonic is then confounded with the C axis' orientation (needs 3 nests).
  bool gamma_cb = false;
  /// Rotations (alpha, beta, gamma) in the tilt map and in the rotary map. Not options: set from
  /// the machine by for_machine (false for an axis on the head: the sphere is one point, so a
  /// head map's rotations only move it, which the map's translations already carry).
  bool b_rotations = true;
  bool c_rotations = true;
  /// The rotary axis points along -Z (it turns clockwise seen from +Z): its first harmonic's
  /// backward-turning pair turns the other way in X, Y. Set by for_machine.
  bool c_reversed = false;

  /// This basis with b_rotations / c_rotations / c_reversed set for machine m (head axes: no
  /// rotations).
  RtestBasis for_machine(MachineType m) const;
  int num_b_coefficients() const;
  int num_c_coefficients() const;
  /// Names "dz_BY.b2", "dx_CB.cos1.b0", ... in coefficient order (tilt map first), with the
  /// machine's map names (rtest_map_names) and its for_machine basis; without a machine,
  /// BC-trt's names of this basis.
  std::vector<std::string> coefficient_names() const;
  std::vector<std::string> coefficient_names(MachineType m) const;
  /// Basis values of w_BY component k (0..5) at B (rad): coefficients of that component.
  std::vector<double> b_terms(int k, double B) const;
  /// Contribution of each C-map coefficient (in order) to w_CB at (B, C) (rad).
  std::vector<AxisErrors<double>> c_terms(double B, double C) const;
  /// Basis values at (B, C) as matrices: w_BY = Lb * (tilt-map coefficients), w_CB = Lc *
  /// (rotary-map coefficients); Lb 6 x num_b_coefficients, Lc 6 x num_c_coefficients. The one
  /// evaluation of the basis, for the fit (rtest/problem.hpp) and the error maps.
  void map_rows(double B, double C, Eigen::Ref<Eigen::MatrixXd> Lb,
                Eigen::Ref<Eigen::MatrixXd> Lc) const;
};

/// Everything needed to predict: location errors, map coefficients and their covariance.
/// On any machine "w_BY" is the tilt axis' map and "w_CB" the rotary axis' map, each applied in
/// front of its own axis' rotation in the chain (rtest_joint_reading).
struct RtestJointModel {
  MachineType machine = MachineType::BC_trt;
  RtestBasis basis;
  /// Parameters in order [8 location errors, tool_offset_Z (machines with head axes only),
  /// tilt-map coefficients, rotary-map coefficients].
  Eigen::VectorXd params;
  /// 1-sigma^2 covariance of params (zero rows/cols for parameters held fixed).
  Eigen::MatrixXd covariance;
  std::vector<bool> observable;  ///< per param

  /// Names of params in order (location_error_names, "tool_offset_Z", coefficient_names(machine)).
  std::vector<std::string> parameter_names() const;
  LocationErrors<double> errors() const;
  /// tool_offset_Z (mm; 0 on a machine without head axes).
  double tool_offset_z() const;
  /// Tilt map w_BY(B) and rotary map w_CB(B, C) (mm, rad) with 1-sigma (NaN where an
  /// unobservable parameter enters); B = tilt, C = rotary angle (rad).
  AxisErrors<double> w_BY(double B, AxisErrors<double>* std = nullptr) const;
  AxisErrors<double> w_CB(double B, double C, AxisErrors<double>* std = nullptr) const;
  /// Pose of the table in the machine frame (identity on a head-head machine).
  Pose<double> table_pose(double B, double C) const;
  /// R-test reading of the nest at q (table frame) at (B, C), without probe zero, with 1 sigma.
  Eigen::Vector3d reading(const Eigen::Vector3d& q, double B, double C,
                          Eigen::Vector3d* std = nullptr) const;
  /// Error of the table point q at (B, C): T q - T_nominal q, machine frame (mm), with 1 sigma.
  Eigen::Vector3d table_error(const Eigen::Vector3d& q, double B, double C,
                              Eigen::Vector3d* std = nullptr) const;
  /// Error of the sphere for the commanded xyz (machine frame, mm): actual - nominal tool ball
  /// (zero on a machine without head axes), with 1 sigma.
  Eigen::Vector3d tool_error(const Eigen::Vector3d& xyz, double B, double C,
                             Eigen::Vector3d* std = nullptr) const;
};

/// One side of the joint model's chain (any Scalar): the product over that side's axes k, in
/// chain order, of E(w_k) Rot(actual line k, angle k), with w_k the tilt map on the tilt axis
/// and the rotary map on the rotary axis (Oyama Eqs. 5-7 on BC-trt's table side). `head`
/// picks the head side (relative to the controlled point); an empty side is the identity.
template <typename Scalar>
Pose<Scalar> rtest_joint_side_pose(MachineType m, const LocationErrors<Scalar>& e,
                                   const AxisErrors<Scalar>& w_BY, const AxisErrors<Scalar>& w_CB,
                                   const RotaryAngles<double>& a, bool head) {
  const int nt = static_cast<int>(m.description().table_axes.size());
  const int k0 = head ? nt : 0, k1 = head ? 2 : nt;
  Pose<Scalar> P;
  for (int k = k0; k < k1; ++k) {
    const AxisLine<Scalar> L = axis_line(m, k, e);
    // Left to right, E then Rot, one factor at a time: BC-trt's numbers stay those of
    // rtest_table_pose to the last bit.
    const Pose<Scalar> E = oyama_error_pose<Scalar>(k == m.rot_index() ? w_CB : w_BY);
    P = k == k0 ? E : Pose<Scalar>(P * E);
    P = P * rotation_about_line(L.point, L.direction, Scalar(chain_angle(m, a, k)));
  }
  return P;
}

/// Templated evaluation of the joint model's table pose (any Scalar): e -> 8 location errors,
/// cb -> tilt-map coefficients, cc -> rotary-map coefficients; the maps w = L c from the
/// basis rows (RtestBasis::map_rows), term by term in coefficient order.
template <typename Scalar>
Pose<Scalar> rtest_joint_table_pose(MachineType m, const RtestBasis& basis, const Scalar* e,
                                    const Scalar* cb, const Scalar* cc, double B, double C) {
  Eigen::MatrixXd Lb(6, basis.num_b_coefficients()), Lc(6, basis.num_c_coefficients());
  basis.map_rows(B, C, Lb, Lc);
  AxisErrors<Scalar> wb = AxisErrors<Scalar>::Zero(), wc = AxisErrors<Scalar>::Zero();
  for (int k = 0; k < 6; ++k) {
    for (Eigen::Index o = 0; o < Lb.cols(); ++o)
      if (Lb(k, o) != 0.0) wb[k] += cb[o] * Scalar(Lb(k, o));
    for (Eigen::Index o = 0; o < Lc.cols(); ++o)
      if (Lc(k, o) != 0.0) wc[k] += cc[o] * Scalar(Lc(k, o));
  }
  return rtest_joint_side_pose<Scalar>(m, LocationErrors<Scalar>::from_ptr(e), wb, wc, {B, C},
                                       false);
}

/// The joint model's R-test reading (rtest/model.hpp) for the sphere commanded to xyz (mm)
/// over the nest at q_nest, at angles a (rad): location errors e, the maps' values w_BY (tilt
/// axis), w_CB (rotary axis) at this pose, and on a machine with head axes tool_offset_Z
/// (mm, along the spindle):
///   d = T^-1 (xyz + H (0, 0, -(pivot_length + tool_length) + tool_offset_Z)) - q_nest
/// with T, H the table and head sides of rtest_joint_side_pose. The joint fit takes Jets of it
/// with respect to (e, w_BY, w_CB, tool_offset_Z); the map coefficients enter through the
/// (linear) basis.
template <typename Scalar>
Vec3<Scalar> rtest_joint_reading(MachineType m, const LocationErrors<Scalar>& e,
                                 const AxisErrors<Scalar>& w_BY, const AxisErrors<Scalar>& w_CB,
                                 const Scalar& tool_offset_z, const RotaryAngles<double>& a,
                                 const Eigen::Vector3d& xyz, const Eigen::Vector3d& q_nest) {
  const Pose<Scalar> T = rtest_joint_side_pose<Scalar>(m, e, w_BY, w_CB, a, false);
  if (!m.has_head()) return rtest_displacement<Scalar>(T, xyz.cast<Scalar>(), q_nest);
  const Pose<Scalar> H = rtest_joint_side_pose<Scalar>(m, e, w_BY, w_CB, a, true);
  const Vec3<Scalar> ball = xyz.cast<Scalar>() + H * tool_vector<Scalar>(m, Scalar(-tool_offset_z));
  return rtest_displacement<Scalar>(T, ball, q_nest);
}

/// BC-trt's form of the same (kept for callers of the paper's machine).
template <typename Scalar>
Vec3<Scalar> rtest_joint_reading(const LocationErrors<Scalar>& e, const AxisErrors<Scalar>& w_BY,
                                 const AxisErrors<Scalar>& w_CB, double B, double C,
                                 const Eigen::Vector3d& xyz, const Eigen::Vector3d& q_nest) {
  return rtest_joint_reading<Scalar>(MachineType::BC_trt, e, w_BY, w_CB, Scalar(0), {B, C}, xyz,
                                     q_nest);
}

struct RtestJointOptions {
  RtestBasis basis;
  int max_iterations = 50;
  /// A direction is unobservable when moving along it by plausible magnitudes (1 mm, 1 mrad)
  /// changes chi-square by less than this (core/least_squares.hpp).
  double observability_min_chi2 = 1.0;
  /// Optional noise model (GLS): maps the residuals in mm (3 per sample, dx dy dz, session
  /// order) to independent unit-variance ones; the covariance is then (Jw^T Jw)^-1 and
  /// summary.chi2_per_dof the whitened one.
  std::shared_ptr<const ResidualWhitener> whitener;
  /// Without a whitener: noise.noise `automatic` estimates the noise model of the first fit's
  /// residuals (one AR stream per nest and channel dx, dy, dz, in time order; probe zeros that
  /// wander between poses show as correlation) and refits by GLS when it is not white, with
  /// REML of AR(1) + a random walk where the streams are short enough (allow_reml).
  /// C++ default `white` because the diagnosis refits through identify_joint with its own
  /// whitener decisions; the Python API and the CLI default to `auto`.
  NoiseFitOptions noise = [] {
    NoiseFitOptions o;
    o.allow_reml = true;
    return o;
  }();
};

/// An R-test identification (core/identification.hpp): `parameters` are the location errors,
/// [tool_offset_Z on a machine with head axes], the map coefficients, then the block "zeros"
/// (dx dy dz per set-up); `residuals` dx dy dz per sample (mm, session order), `noise` one
/// stream per nest and channel. It adds the identified model with its maps.
struct RtestJointIdentification : Identification {
  RtestJointModel model;
  std::map<std::string, Eigen::Vector3d> probe_zeros;  ///< per set-up, mm (the block "zeros")

  /// measured - model of sample i (mm): residuals 3i .. 3i + 2.
  Eigen::Vector3d residual(std::size_t i) const {
    return Eigen::Vector3d(residuals[3 * i], residuals[3 * i + 1], residuals[3 * i + 2]);
  }
};

/// Fit the joint model to every sample, on any machine. Throws InvalidArgument for samples
/// without d (convert raw readings first: device.hpp), unknown nests, or fewer
/// readings than unknowns.
RtestJointIdentification identify_joint(const RtestSession& session,
                                        const RtestJointOptions& options = {});

}  // namespace rotacal
