// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one place where numpy arrays become Eigen types and back. Binding files use these and
/// nothing else, so shape checks and their messages are the same everywhere.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/effects.hpp"

namespace rotacal::py {

namespace pyb = pybind11;

/// An (N, K) float64 array as a row-major Eigen matrix (copy; N may be 0).
template <int K>
Eigen::Matrix<double, Eigen::Dynamic, K, (K == 1 ? Eigen::ColMajor : Eigen::RowMajor)> rows_of(
    const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& a, const char* name) {
  if (a.ndim() != 2 || a.shape(1) != K)
    throw InvalidArgument(std::string(name) + ": expected an array of shape (N, " +
                          std::to_string(K) + ")");
  Eigen::Matrix<double, Eigen::Dynamic, K, (K == 1 ? Eigen::ColMajor : Eigen::RowMajor)> m(
      a.shape(0), K);
  std::copy(a.data(), a.data() + a.size(), m.data());
  return m;
}

/// A length-K float64 vector.
template <int K>
Eigen::Matrix<double, K, 1> vec_of(
    const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& a, const char* name) {
  if (a.ndim() != 1 || a.shape(0) != K)
    throw InvalidArgument(std::string(name) + ": expected an array of shape (" + std::to_string(K) +
                          ",)");
  Eigen::Matrix<double, K, 1> v;
  std::copy(a.data(), a.data() + K, v.data());
  return v;
}

using Array = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>;
using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// An (N, 3) array as N vectors.
inline std::vector<Eigen::Vector3d> vectors_of(const Array& a, const char* name) {
  const auto m = rows_of<3>(a, name);
  std::vector<Eigen::Vector3d> out;
  for (Eigen::Index i = 0; i < m.rows(); ++i) out.emplace_back(m.row(i).transpose());
  return out;
}

/// N vectors as an (N, 3) array.
inline Rows3 rows_from(const std::vector<Eigen::Vector3d>& v) {
  Rows3 m(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  return m;
}

/// A (3, 3) array.
inline Eigen::Matrix3d matrix3_of(const Array& a, const char* name) {
  const auto m = rows_of<3>(a, name);
  if (m.rows() != 3)
    throw InvalidArgument(std::string(name) + ": expected an array of shape (3, 3)");
  return m;
}

/// Catalogue ids (shared/spec/effects.md) as an effect model, and back.
inline EffectModel effects_of(const std::vector<std::string>& ids) {
  EffectModel fx;
  for (const std::string& id : ids) fx.effects.push_back(Effect::parse(id));
  return fx;
}
inline std::vector<std::string> ids_of(const EffectModel& fx) {
  std::vector<std::string> ids;
  for (const Effect& e : fx.effects) ids.push_back(e.id());
  return ids;
}

/// A (done, total) progress callback for long C++ work that calls a Python callable with the
/// GIL taken (the work runs with it released); empty for None.
inline std::function<void(int, int)> progress_callback(const pyb::object& progress) {
  if (progress.is_none()) return {};
  return [&progress](int done, int total) {
    pyb::gil_scoped_acquire acquire;
    progress(done, total);
  };
}

}  // namespace rotacal::py
