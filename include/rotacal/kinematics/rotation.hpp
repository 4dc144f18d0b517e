// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Rigid rotations used by every kinematic formula in rotacal: rotation about an arbitrary line
/// (Flynn et al. 2016, Eq. 1) and the elementary homogeneous transforms D_x..D_c
/// (Oyama & Ibaraki, Eq. 1). Templated on Scalar so ceres::Jet flows through.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace rotacal {

template <typename Scalar>
using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
template <typename Scalar>
using Mat4 = Eigen::Matrix<Scalar, 4, 4>;

/// Rigid transform p -> R p + t. Kept as a plain (R, t) pair rather than Eigen::Transform so
/// that Jets, composition and inversion are explicit and cheap.
template <typename Scalar>
struct Pose {
  Mat3<Scalar> R = Mat3<Scalar>::Identity();
  Vec3<Scalar> t = Vec3<Scalar>::Zero();

  Vec3<Scalar> operator*(const Vec3<Scalar>& p) const { return R * p + t; }
  Pose operator*(const Pose& o) const { return {R * o.R, R * o.t + t}; }
  Pose inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
  Mat4<Scalar> matrix() const {
    Mat4<Scalar> m = Mat4<Scalar>::Identity();
    m.template topLeftCorner<3, 3>() = R;
    m.template topRightCorner<3, 1>() = t;
    return m;
  }
  template <typename Other>
  Pose<Other> cast() const {
    return {R.template cast<Other>(), t.template cast<Other>()};
  }
};

/// Rotation matrix for angle theta (rad) about unit axis u (Rodrigues).
template <typename Scalar>
Mat3<Scalar> rotation_about_axis(const Vec3<Scalar>& u, const Scalar& theta) {
  using std::cos;
  using std::sin;
  Mat3<Scalar> K;
  K << Scalar(0), -u.z(), u.y(), u.z(), Scalar(0), -u.x(), -u.y(), u.x(), Scalar(0);
  return Mat3<Scalar>::Identity() + sin(theta) * K + (Scalar(1) - cos(theta)) * (K * K);
}

/// Rotation by theta (rad, right-handed) about the line through `point` with direction
/// `direction` (any non-zero length; it is normalised here so that ISO 230-7 directions such
/// as (1, E_C0A, -E_B0A) can be passed as they are). Flynn et al. 2016, Eq. 1, in matrix form:
/// x' = R (x - a) + a.
template <typename Scalar>
Pose<Scalar> rotation_about_line(const Vec3<Scalar>& point, const Vec3<Scalar>& direction,
                                 const Scalar& theta) {
  const Vec3<Scalar> u = direction / direction.norm();
  Pose<Scalar> T;
  T.R = rotation_about_axis<Scalar>(u, theta);
  T.t = point - T.R * point;
  return T;
}

/// Rotate the point q by theta (rad) about the line through `point` along `direction` (any
/// non-zero length): the vector form of Flynn et al. 2016, Eq. 1,
///   q' = a + v cos(theta) + (u x v) sin(theta) + u (u . v) (1 - cos(theta)),  v = q - a.
/// Cheaper than building the Pose when only one point is needed (the ballbar's pivot).
/// This form takes c = cos(theta) and s = sin(theta) (the analytic Jacobian has them already);
/// the form below takes theta.
/// The form with a unit direction u is the one body; the others normalise and call it.
template <typename Scalar>
Vec3<Scalar> rotate_point_about_unit_line(const Vec3<Scalar>& point, const Vec3<Scalar>& u,
                                          const Scalar& c, const Scalar& s, const Vec3<Scalar>& q) {
  const Vec3<Scalar> v = q - point;
  return point + v * c + u.cross(v) * s + u * (u.dot(v) * (Scalar(1) - c));
}
template <typename Scalar>
Vec3<Scalar> rotate_point_about_line(const Vec3<Scalar>& point, const Vec3<Scalar>& direction,
                                     const Scalar& c, const Scalar& s, const Vec3<Scalar>& q) {
  return rotate_point_about_unit_line<Scalar>(point, Vec3<Scalar>(direction / direction.norm()), c,
                                              s, q);
}
template <typename Scalar>
Vec3<Scalar> rotate_point_about_line(const Vec3<Scalar>& point, const Vec3<Scalar>& direction,
                                     const Scalar& theta, const Vec3<Scalar>& q) {
  using std::cos;
  using std::sin;
  return rotate_point_about_line<Scalar>(point, direction, Scalar(cos(theta)), Scalar(sin(theta)),
                                         q);
}

/// rotate_point_about_line with its first derivatives (double, or Lanes of four samples: the
/// fits' fast path, checked against Jets of rotate_point_about_line in
/// tests/cpp/test_rotation.cpp):
///   f = a + R(u, theta) (q - a),  u = d / |d|,  v = q - a
///   df/dq = R,  df/da = I - R,
///   df/dd = [-sin(theta) [v]x + (1 - cos(theta)) ((u . v) I + u v^T)] (I - u u^T) / |d|.
/// A chain rule runs from the reading backwards, so the derivatives are applied to row vectors
/// w (w df/dq and so on, a few cross products each); the matrices are for tests.
template <typename Scalar = double>
struct LineRotationDerivatives {
  using Row = Eigen::Matrix<Scalar, 1, 3>;
  Vec3<Scalar> f, u, v;
  Scalar c = Scalar(1), s = Scalar(0), inv_norm = Scalar(1);

  /// w R, with w K = w x u for the row w and K = [u]x.
  Row times_q(const Row& w) const {
    const Vec3<Scalar> wk = w.transpose().cross(u);
    return w + (s * wk + (Scalar(1) - c) * wk.cross(u)).transpose();
  }
  /// w (I - R): pass w R when the caller has it (a chain rule needs both).
  Row times_point(const Row& w) const { return w - times_q(w); }
  Row times_point(const Row& w, const Row& w_times_q) const { return w - w_times_q; }
  Row times_direction(const Row& w) const {
    const Vec3<Scalar> g = times_unit_direction(w).transpose();
    return ((g - g.dot(u) * u) * inv_norm).transpose();
  }
  /// w df/du for the unit direction u itself; times_direction is this times
  /// du/dd = (I - u u^T) / |d|, which a caller with many points on one line applies once.
  Row times_unit_direction(const Row& w) const {
    const Vec3<Scalar> wt = w.transpose();
    return (-s * wt.cross(v) + (Scalar(1) - c) * (u.dot(v) * wt + wt.dot(u) * v)).transpose();
  }
  Mat3<Scalar> d_q() const {
    return rows([this](const Row& w) { return times_q(w); });
  }
  Mat3<Scalar> d_point() const {
    return rows([this](const Row& w) { return times_point(w); });
  }
  Mat3<Scalar> d_direction() const {
    return rows([this](const Row& w) { return times_direction(w); });
  }

 private:
  template <typename F>
  static Mat3<Scalar> rows(const F& times) {
    Mat3<Scalar> M;
    for (int r = 0; r < 3; ++r) M.row(r) = times(Row::Unit(r));
    return M;
  }
};

/// The form for a line given as its point, unit direction u = d / |d| and 1 / |d|, and the
/// angle as c = cos(theta), s = sin(theta): a fit evaluates the line once per parameter vector
/// and the commanded angles' sines once per session. Scalar double, or Lanes (core/lanes.hpp)
/// for four samples at once.
template <typename Scalar>
LineRotationDerivatives<Scalar> rotate_point_about_unit_line_derivatives(
    const Vec3<Scalar>& point, const Vec3<Scalar>& u, const Scalar& inv_norm, const Scalar& c,
    const Scalar& s, const Vec3<Scalar>& q) {
  LineRotationDerivatives<Scalar> D;
  D.inv_norm = inv_norm;
  D.u = u;
  D.v = q - point;
  D.c = c;
  D.s = s;
  D.f = rotate_point_about_unit_line<Scalar>(point, u, c, s, q);  // the one definition
  return D;
}
inline LineRotationDerivatives<double> rotate_point_about_line_derivatives(
    const Eigen::Vector3d& point, const Eigen::Vector3d& direction, double theta,
    const Eigen::Vector3d& q) {
  const double inv_norm = 1.0 / direction.norm();
  return rotate_point_about_unit_line_derivatives<double>(point, direction * inv_norm, inv_norm,
                                                          std::cos(theta), std::sin(theta), q);
}

/// Flynn et al. 2016, Eq. 1 written out component by component: rotates q = (x, y, z) about
/// the line through (a, b, c) with unit direction (u, v, w). The y row as printed in the paper
/// has two sign slips ("cu + aw - wx + uz"); this is the standard form, "cu - aw + wx - uz".
/// Kept as the reference the matrix form above is tested against.
template <typename Scalar>
Vec3<Scalar> flynn_eq1(const Vec3<Scalar>& q, const Vec3<Scalar>& abc, const Vec3<Scalar>& uvw,
                       const Scalar& theta) {
  using std::cos;
  using std::sin;
  const Scalar x = q.x(), y = q.y(), z = q.z();
  const Scalar a = abc.x(), b = abc.y(), c = abc.z();
  const Scalar u = uvw.x(), v = uvw.y(), w = uvw.z();
  const Scalar C = cos(theta), S = sin(theta), K = Scalar(1) - C;
  const Scalar dot = u * x + v * y + w * z;
  return Vec3<Scalar>((a * (v * v + w * w) - u * (b * v + c * w - dot)) * K + x * C +
                          (-c * v + b * w - w * y + v * z) * S,
                      (b * (u * u + w * w) - v * (a * u + c * w - dot)) * K + y * C +
                          (c * u - a * w + w * x - u * z) * S,
                      (c * (u * u + v * v) - w * (a * u + b * v - dot)) * K + z * C +
                          (-b * u + a * v - v * x + u * y) * S);
}

/// Elementary homogeneous transforms of Oyama & Ibaraki, Eq. 1.
template <typename Scalar>
Mat4<Scalar> D_x(const Scalar& X) {
  Mat4<Scalar> m = Mat4<Scalar>::Identity();
  m(0, 3) = X;
  return m;
}
template <typename Scalar>
Mat4<Scalar> D_y(const Scalar& Y) {
  Mat4<Scalar> m = Mat4<Scalar>::Identity();
  m(1, 3) = Y;
  return m;
}
template <typename Scalar>
Mat4<Scalar> D_z(const Scalar& Z) {
  Mat4<Scalar> m = Mat4<Scalar>::Identity();
  m(2, 3) = Z;
  return m;
}
template <typename Scalar>
Mat4<Scalar> D_a(const Scalar& A) {
  Mat4<Scalar> m = Mat4<Scalar>::Identity();
  m.template topLeftCorner<3, 3>() = rotation_about_axis<Scalar>(Vec3<Scalar>::UnitX(), A);
  return m;
}
template <typename Scalar>
Mat4<Scalar> D_b(const Scalar& B) {
  Mat4<Scalar> m = Mat4<Scalar>::Identity();
  m.template topLeftCorner<3, 3>() = rotation_about_axis<Scalar>(Vec3<Scalar>::UnitY(), B);
  return m;
}
template <typename Scalar>
Mat4<Scalar> D_c(const Scalar& C) {
  Mat4<Scalar> m = Mat4<Scalar>::Identity();
  m.template topLeftCorner<3, 3>() = rotation_about_axis<Scalar>(Vec3<Scalar>::UnitZ(), C);
  return m;
}

}  // namespace rotacal
