// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Touch-probe simulator (issue 31, item 2): the touch geometry of ../shared/spec/formats.md
/// on any machine. At each pose, held at rest, the probe moves along the line through the
/// sphere's nominal centre (placed by the nominal machine) along each approach direction n and
/// triggers where touch_residual (probe/touch_model.hpp) is zero on the machine `truth`
/// (location errors, catalogue effects, stylus_radius_offset); the latched position then
/// moves along n by probe_lobing, and Gaussian noise (white, or AR(1) from touch to touch) is
/// added to each latched coordinate.

#include <cstdint>
#include <optional>
#include <vector>

#include "rotacal/kinematics/machine_model.hpp"
#include "rotacal/session/probe_session.hpp"
#include "rotacal/session/thermal_test.hpp"

namespace rotacal {

/// Poses, approach directions and the artefact.
struct ProbePattern {
  std::vector<RotaryAngles<double>> poses_deg;  ///< tilt and rotary angle of each pose, deg
  std::vector<Eigen::Vector3d> directions;      ///< approach directions, machine frame (normalised)
  /// Each pose's own approach directions (machine frame), one list per pose, in touch order
  /// (`rotacal design probe` chooses each touch's); empty: `directions` at every pose.
  std::vector<std::vector<Eigen::Vector3d>> pose_directions;
  Eigen::Vector3d sphere = Eigen::Vector3d(150.0, 0.0, 80.0);  ///< nominal centre, table frame, mm
  double sphere_diameter = 25.0;                               ///< mm
  double stylus_diameter = 6.0;                                ///< mm
  double touch_dt_s = 2.0;  ///< time between the touches of a pose, s
  double pose_dt_s = 16.0;  ///< time between the first touches of successive poses, s

  /// The approach directions of pose k (0-based).
  const std::vector<Eigen::Vector3d>& directions_at(std::size_t k) const {
    return pose_directions.empty() ? directions : pose_directions[k];
  }
  /// Touches of the whole pattern.
  std::size_t touch_count() const {
    if (pose_directions.empty()) return poses_deg.size() * directions.size();
    std::size_t n = 0;
    for (const auto& d : pose_directions) n += d.size();
    return n;
  }
};

/// The pattern of the controller cycles as shared/data/probe_ac_table2.csv has it: 12 poses of
/// the rotary axis every 30 deg at tilt 0, then 12 tilts at rotary 0 (13 over -90..90 deg,
/// clipped to the tilt axis' limits, without 0); at each pose one touch from above and four at
/// 30 deg below the horizontal along -X, -Y, +X, +Y turned towards the centre.
ProbePattern default_probe_pattern(MachineType m);

struct ProbeSimOptions {
  ProbePattern pattern;
  /// Actual minus nominal sphere centre, table frame, mm (the set-up error).
  Eigen::Vector3d sphere_offset = Eigen::Vector3d::Zero();
  double noise_um = 0.5;  ///< 1 sigma of each latched coordinate, um (0: none)
  double ar1_rho = 0.0;   ///< correlation of each coordinate's noise from one touch to the next
  std::uint64_t seed = 1;
  /// A thermal test (formats.md): the pattern once per epoch, the machine's location errors and
  /// the sphere drifting as thermal_location_R between and during them. None: one pass from 0 s.
  std::optional<ThermalSimSpec> thermal;
};

struct ProbeSimulation {
  ProbeSession session;
  Eigen::Vector3d sphere_actual = Eigen::Vector3d::Zero();  ///< table frame, mm (cold)
  ThermalTest thermal;  ///< with options.thermal: the duty, each touch's epoch and time
};

/// Simulate a whole session. Throws InvalidArgument for an empty pattern, a zero direction,
/// pose_directions not one non-empty list per pose,
/// negative noise, |ar1_rho| >= 1, a direction along which the probe misses the sphere, a
/// truth model whose effects do not fit its machine, or a thermal spec ThermalSimSpec::validate
/// refuses.
ProbeSimulation simulate_probe(const MachineModel& truth, const ProbeSimOptions& options = {});

}  // namespace rotacal
