// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Identification of a touch-probe session (issue 31, item 3):
/// - `identify_probe`: the joint fit of every touch (probe/problem.hpp) through the one
///   joint-fit driver with its noise model (core/fit_with_noise.hpp): the location errors
///   and the sphere's actual table position, the calibrated radius as given, a 1-sigma
///   covariance and what the session cannot see.
/// - `identify_probe_cycles`: the controller cycles' own method as the peer (HEIDENHAIN
///   KinematicsOpt cycle 451, ISG SysMeasRotAx): a sphere fit per pose, then per rotary axis a
///   plane and a circle through the centres of the poses that turn that axis alone; the
///   plane's normal is the axis' direction, the circle's centre a point of its line.

#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/identification.hpp"
#include "rotacal/kinematics/machine_model.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

struct ProbeFitOptions {
  EffectModel effects;  ///< catalogue effects fitted along (the diagnosis); they start at 0
  int max_iterations = 100;
  /// A direction is unobservable when moving along it by plausible magnitudes (1 mm, 1 mrad)
  /// changes chi-square by less than this.
  double observability_min_chi2 = 1.0;
  /// Optional GLS whitener of the touch residuals (mm, session order); then no noise model is
  /// estimated.
  std::shared_ptr<const ResidualWhitener> whitener;
  /// Noise model of the residuals (one stream: the touches in time order) and GLS refit.
  /// C++ default `white`, as the ballbar and R-test fits (the diagnosis makes its own
  /// whitener decisions); the Python API defaults to `auto`.
  NoiseFitOptions noise = [] {
    NoiseFitOptions o;
    o.noise = NoiseHandling::white;
    return o;
  }();
};

/// A touch-probe identification (core/identification.hpp). Joint: `parameters` are the
/// location errors, [tool_offset_Z on a machine with head axes], the block "sphere" (x y z),
/// the effect parameters; `residuals` one per touch (mm, session order): the trigger distance
/// (D + d)/2 (+ delta) minus the touch's distance from the fitted sphere centre. Cycles: the
/// location errors only, with std NaN (the cycles give no uncertainty) and no covariance.
struct ProbeIdentification : Identification {
  /// Identified machine: location errors (unobservable ones left at 0), the fitted effects and
  /// their values.
  MachineModel model;
  Eigen::Vector3d sphere = Eigen::Vector3d::Zero();  ///< actual sphere centre (block "sphere")
  /// Cycles: the sphere centre fitted at each pose (machine frame, mm), the poses' labels and
  /// the dispersion of the centres about the fitted circles (RMS, um): what the controller
  /// cycles report instead of an uncertainty.
  std::vector<Eigen::Vector3d> pose_centres;
  std::vector<std::string> pose_labels;
  double dispersion_um = 0.0;
};

/// Joint fit of every touch. Throws InvalidArgument for a session with fewer touches than
/// unknowns or an effect that does not exist on its machine.
ProbeIdentification identify_probe(const ProbeSession& session,
                                   const ProbeFitOptions& options = {});

struct ProbeCyclesOptions {
  /// Fit each pose's sphere with the calibrated radius (D + d)/2 (true) or with a free radius
  /// (false, at least 4 touches not in one plane per pose).
  bool radius_known = true;
};

/// The cycles' method on a machine with two table axes (the cycles measure the table's axes;
/// the sphere then turns with them). Throws InvalidArgument for a machine with head axes and
/// DegenerateGeometry, naming the pose or axis, when a pose has too few touches for its sphere
/// or an axis fewer than 3 poses turned about it alone.
ProbeIdentification identify_probe_cycles(const ProbeSession& session,
                                          const ProbeCyclesOptions& options = {});

}  // namespace rotacal
