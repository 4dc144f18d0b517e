// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The angle constants of the library's sources, defined once: file-local copies of them clashed
/// when the sources are compiled together in unity batches (top CMakeLists.txt).

namespace rotacal {

inline constexpr double kPi = 3.14159265358979323846;
/// Radians per degree.
inline constexpr double kDeg = kPi / 180.0;

}  // namespace rotacal
