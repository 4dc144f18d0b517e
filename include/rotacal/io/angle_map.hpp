// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The errors of a model that move with a rotary axis, as functions of that axis' angle: the
/// source of every controller's compensation table (docs/controller_exports.md, "Angle maps").
///
/// A model holds position-dependent errors in one of two forms, and each is evaluated here by
/// its own code, never by a second formula:
///   - an R-test joint model ("rtest-joint"): the tilt map w_BY(tilt) and the rotary map
///     w_CB(tilt, rot) (rtest/identify_joint.hpp), taken at the other axis' 0;
///   - catalogue effects (any other kind: a diagnosis' extended model, a probe or multi fit):
///     the stages of one axis as kinematics/effects.hpp walks them (zero offset, angular
///     positioning, radial / axial / tilt motion harmonics, coning, gravity sag).
/// The location errors are left out: the kinematic parameters hold them (controller_export.hpp).
/// Here the terms' types and their sampling; the functions of a model, which need the R-test
/// layer: compensation/axis_errors.hpp.
///
/// The terms of axis k are the ISO 230-1 error motions of that axis in the frame it is mounted
/// in, with the other axis at 0: the small transform Delta(angle) = actual motion * nominal
/// motion^-1, taken about the axis' nominal point, as
///   E_X, E_Y, E_Z (mm, machine X, Y, Z) and E_A, E_B, E_C (rad, Delta's rotation as
///   Rx(E_A) Ry(E_B) Rz(E_C), oyama_errors_of),
/// plus the positioning error (rad), actual minus commanded angle: the Euler component about
/// the axis' own principal direction (E_CC of a C along +Z, -E_CC along -Z), for a nutating
/// axis Delta's rotation vector along its direction. Names: "E_XC" ... "E_CC", "positioning_C".

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "rotacal/io/model_file.hpp"

namespace rotacal {

/// Number of terms of an axis: six error motions and the positioning error.
inline constexpr int kAngleMapTerms = 7;
using AngleMapTerms = Eigen::Matrix<double, kAngleMapTerms, 1>;

/// Terms of one rotary axis as a function of its commanded angle (rad), the model's own
/// evaluation. `axis` the letter, `chain_index` its index in the machine's chain.
struct AxisErrorFunction {
  char axis = 'C';
  int chain_index = 0;
  std::array<std::string, kAngleMapTerms> names;  ///< "E_XC", ..., "E_CC", "positioning_C"
  std::array<std::string, kAngleMapTerms> units;  ///< "mm" x3, "rad" x4
  std::vector<std::string>
      sources;                     ///< the model's terms that feed it ("angular_positioning_C_h1")
  std::vector<std::string> notes;  ///< what the function leaves out, in words
  std::function<AngleMapTerms(double angle_rad)> evaluate;
};

/// One axis' terms at equally spaced angles.
struct AxisAngleMap {
  char axis = 'C';
  double lo_deg = 0.0, hi_deg = 0.0, spacing_deg = 0.0;
  std::array<std::string, kAngleMapTerms> names, units;
  std::vector<std::string> sources, notes;
  std::vector<double> angle_deg;  ///< lo_deg + i spacing_deg, up to hi_deg
  Eigen::Matrix<double, Eigen::Dynamic, kAngleMapTerms> values;  ///< a row per angle
  /// Worst |model - linear interpolation of the points| per term, the model evaluated at
  /// `samples_between` equally spaced angles inside every interval.
  AngleMapTerms max_interpolation_error = AngleMapTerms::Zero();
  AngleMapTerms max_abs = AngleMapTerms::Zero();  ///< largest |value| at the points
  int samples_between = 0;
};

/// Equally spaced angles lo, lo + spacing, ..., hi (deg). InvalidArgument naming `option` when
/// hi <= lo, spacing <= 0, or (hi - lo) is not a whole number of spacings (to 1e-9 of one).
std::vector<double> equally_spaced_deg(double lo_deg, double hi_deg, double spacing_deg,
                                       const std::string& option);

/// The function sampled at `equally_spaced_deg(lo, hi, spacing)` with its worst interpolation
/// error (samples_between >= 1 model evaluations inside each interval).
AxisAngleMap sample_angle_map(const AxisErrorFunction& f, double lo_deg, double hi_deg,
                              double spacing_deg, int samples_between = 16);

/// Worst |f(x) - linear interpolation of `at_grid` between the grid points| over the grid points
/// (where a table's written values may be rounded) and `samples_between` equally spaced x inside
/// each interval of `grid` (increasing): the one estimate of every table's interpolation error.
double worst_interpolation_error(const std::vector<double>& grid,
                                 const std::vector<double>& at_grid,
                                 const std::function<double(double)>& f, int samples_between);

}  // namespace rotacal
