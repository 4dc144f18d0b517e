// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Lanes: a scalar that holds one quantity of four samples at once, so that a kinematic formula
/// templated on Scalar (kinematics/rotation.hpp) evaluates four samples per call in SIMD
/// registers. Eigen's fixed 3-vectors of doubles are not vectorised (3 is not a multiple of the
/// packet size), so a sample-by-sample evaluation runs on scalar instructions; with Lanes each
/// operation is one packet operation on the same four lanes (Eigen::Array4d), the way Jets carry
/// their derivatives through the same formulas. Only the arithmetic the formulas use is defined.
#include <Eigen/Core>
#include <cmath>
#include <limits>

namespace rotacal {

struct Lanes {
  static constexpr int kSize = 4;
  Eigen::Array4d v;

  Lanes() = default;
  /// A constant is the same in every lane (as a double becomes a Jet with zero derivatives).
  Lanes(double x) : v(Eigen::Array4d::Constant(x)) {}  // NOLINT(google-explicit-constructor)
  explicit Lanes(const Eigen::Array4d& a) : v(a) {}

  double operator[](int lane) const { return v[lane]; }
  double& operator[](int lane) { return v[lane]; }

  Lanes& operator+=(const Lanes& o) {
    v += o.v;
    return *this;
  }
  Lanes& operator-=(const Lanes& o) {
    v -= o.v;
    return *this;
  }
  Lanes& operator*=(const Lanes& o) {
    v *= o.v;
    return *this;
  }
  Lanes& operator/=(const Lanes& o) {
    v /= o.v;
    return *this;
  }
};

inline Lanes operator+(const Lanes& a, const Lanes& b) { return Lanes(Eigen::Array4d(a.v + b.v)); }
inline Lanes operator-(const Lanes& a, const Lanes& b) { return Lanes(Eigen::Array4d(a.v - b.v)); }
inline Lanes operator*(const Lanes& a, const Lanes& b) { return Lanes(Eigen::Array4d(a.v * b.v)); }
inline Lanes operator/(const Lanes& a, const Lanes& b) { return Lanes(Eigen::Array4d(a.v / b.v)); }
inline Lanes operator-(const Lanes& a) { return Lanes(Eigen::Array4d(-a.v)); }
inline Lanes sqrt(const Lanes& a) { return Lanes(Eigen::Array4d(a.v.sqrt())); }

}  // namespace rotacal

namespace Eigen {
template <>
struct NumTraits<rotacal::Lanes> : GenericNumTraits<double> {
  using Real = rotacal::Lanes;
  using NonInteger = rotacal::Lanes;
  using Nested = rotacal::Lanes;
  using Literal = rotacal::Lanes;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 1,
    MulCost = 1
  };
  static Real epsilon() { return Real(std::numeric_limits<double>::epsilon()); }
  static Real dummy_precision() { return Real(1e-12); }
  static Real highest() { return Real(std::numeric_limits<double>::max()); }
  static Real lowest() { return Real(std::numeric_limits<double>::lowest()); }
  static int digits10() { return std::numeric_limits<double>::digits10; }
};
}  // namespace Eigen
