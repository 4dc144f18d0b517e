// SPDX-License-Identifier: BSD-3-Clause
// Oyama's error model: Euler angles of a pose, and the exact and first-order maps from location
// errors.
#include "rotacal/rtest/error_model.hpp"

#include <cmath>

namespace rotacal {

AxisErrors<double> oyama_errors_of(const Pose<double>& P) {
  // R = Rx(a) Ry(b) Rz(c): R(0,2) = sin b, R(1,2) = -sin a cos b, R(2,2) = cos a cos b,
  // R(0,1) = -cos b sin c, R(0,0) = cos b cos c.
  const Eigen::Matrix3d& R = P.R;
  AxisErrors<double> w;
  w.head<3>() = P.t;
  w[4] = std::asin(std::max(-1.0, std::min(1.0, R(0, 2))));
  w[3] = std::atan2(-R(1, 2), R(2, 2));
  w[5] = std::atan2(-R(0, 1), R(0, 0));
  return w;
}

OyamaConstantErrors oyama_from_location(const LocationErrors<double>& e) {
  const Eigen::Vector3d a(e.v[0], 0.0, e.v[1]);
  const Eigen::Vector3d c(e.v[4], e.v[5], 0.0);
  const double nB = Eigen::Vector3d(-e.v[3], 1.0, e.v[2]).norm();
  const double nC = Eigen::Vector3d(e.v[7], -e.v[6], 1.0).norm();
  const Eigen::Matrix3d R0 =
      rotation_about_axis<double>(Eigen::Vector3d::UnitX(), std::atan(e.v[2])) *
      rotation_about_axis<double>(Eigen::Vector3d::UnitZ(), std::asin(e.v[3] / nB));
  const Eigen::Matrix3d R1 =
      rotation_about_axis<double>(Eigen::Vector3d::UnitX(), std::atan(e.v[6])) *
      rotation_about_axis<double>(Eigen::Vector3d::UnitY(), std::asin(e.v[7] / nC));
  OyamaConstantErrors out;
  out.w_BY = oyama_errors_of(Pose<double>{R0, a});
  out.w_CB = oyama_errors_of(Pose<double>{R0.transpose() * R1, R0.transpose() * (c - a)});
  out.F = Pose<double>{R1.transpose(), -(R1.transpose() * c)};
  return out;
}

OyamaConstantErrors oyama_from_location_first_order(const LocationErrors<double>& e) {
  OyamaConstantErrors out;
  out.w_BY << e.v[0], 0.0, e.v[1], e.v[2], 0.0, e.v[3];
  out.w_CB << e.v[4] - e.v[0], e.v[5], -e.v[1], e.v[6] - e.v[2], e.v[7], -e.v[3];
  // F = R1^T Tr(-c) to first order: rotation -(E_A0C, E_B0C, 0), translation -c.
  out.F.R = rotation_about_axis<double>(Eigen::Vector3d::UnitX(), -e.v[6]) *
            rotation_about_axis<double>(Eigen::Vector3d::UnitY(), -e.v[7]);
  out.F.t = -Eigen::Vector3d(e.v[4], e.v[5], 0.0);
  return out;
}

std::string oyama_error_name(int k, const std::string& axis) {
  static const char* n[6] = {"dx", "dy", "dz", "alpha", "beta", "gamma"};
  if (k < 0 || k > 5) throw InvalidArgument("oyama_error_name: k must be in 0..5");
  return std::string(n[k]) + "_" + axis;
}

}  // namespace rotacal
