// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The designs' number format in words: fixed point with a given number of digits.

#include <Eigen/Core>
#include <sstream>
#include <string>

namespace rotacal {

/// v in fixed point with `digits` decimals ("12.5").
inline std::string fixed_text(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

/// A point in mm with one decimal: "(x, y, z) mm".
inline std::string point_text(const Eigen::Vector3d& v) {
  return "(" + fixed_text(v[0]) + ", " + fixed_text(v[1]) + ", " + fixed_text(v[2]) + ") mm";
}

}  // namespace rotacal
