#pragma once
/// \file
/// The one place where numpy arrays become Eigen types and back. Binding files use these and
/// nothing else, so shape checks and their messages are the same everywhere.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <string>

#include "rotacal/core/error.hpp"

namespace rotacal::py {

namespace pyb = pybind11;

/// An (N, K) float64 array as a row-major Eigen matrix (copy; N may be 0).
template <int K>
Eigen::Matrix<double, Eigen::Dynamic, K, (K == 1 ? Eigen::ColMajor : Eigen::RowMajor)> rows_of(
    const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& a,
    const char* name) {
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
    const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& a,
    const char* name) {
  if (a.ndim() != 1 || a.shape(0) != K)
    throw InvalidArgument(std::string(name) + ": expected an array of shape (" +
                          std::to_string(K) + ",)");
  Eigen::Matrix<double, K, 1> v;
  std::copy(a.data(), a.data() + K, v.data());
  return v;
}

}  // namespace rotacal::py
