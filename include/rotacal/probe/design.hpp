// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Design of the touch-probe test before the machine runs it (`rotacal design probe`): the
/// rotary poses (within the machine's axis limits, each plannable by probe/nc_program.hpp) and
/// the touches per pose whose joint fit (probe/problem.hpp: location errors, tool_offset_Z on
/// a head, the sphere) gives the smallest largest expanded uncertainty (k = 2) of the location
/// errors at a given number of touches, and the same for `plan probe`'s default poses.
///
/// Touch by touch (`touch_directions`; the CLI's default): each candidate is one touch at a grid
/// pose along one direction of contact_directions (the contact point within `max_contact_angle_deg`
/// of the stylus axis, polar every `contact_step_deg`, azimuth every 45 deg), each checked alone
/// by probe_moves (travel, the way up clear of the sphere); the engine allocates the touches, and
/// the designed pattern touches each chosen pose along its own directions (pose_directions).
/// The sphere: `sphere` (the default set-up) and each of `sphere_candidates` (the engineer
/// places it; the design says where): the design at each, the one with the smallest largest
/// expanded uncertainty taken when it is `sphere_gain` below the design at `sphere`. The default
/// poses are always judged at `sphere`.
///
/// Information: the probe problem's Jacobian at the fit's start point on the nominal machine's
/// commanded touches (simulate_probe without errors or noise), over white noise of `noise_um`
/// per touch: each touch reads the sphere's centre along its approach direction, so the noise
/// of a residual is that of a latched coordinate. Every candidate pose (a grid over the axis
/// limits) is touched along the same approach directions (`directions`, default the default
/// pattern's five: one from above, four at 30 deg below the horizontal), as `plan probe
/// --poses` touches every pose; the design engine (design/allocation.hpp) allocates pose visits
/// (touches / directions of them; a pose visited v times is touched v times along each
/// direction) for the smallest largest 2 sigma (an orientation error counts as its value times
/// `reference_radius_mm`). The default poses are evaluated at the same number of touches
/// (their information scaled by touches / their own touches).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "rotacal/design/separation.hpp"
#include "rotacal/probe/nc_program.hpp"
#include "rotacal/probe/simulate.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

struct ProbeDesignOptions {
  MachineType machine = MachineType::AC_trt;
  Eigen::Vector3d sphere = Eigen::Vector3d(150.0, 0.0, 80.0);  ///< nominal centre, table frame, mm
  double sphere_diameter = 25.0;                               ///< mm
  double stylus_diameter = 6.0;                                ///< mm
  int touches = 0;  ///< total touches; 0: the default poses' (default_probe_pattern)
  std::vector<Eigen::Vector3d>
      directions;  ///< approach directions, machine frame; empty: the default pattern's
  double tilt_step_deg =
      15.0;  ///< candidate tilts: the tilt axis' limits (-90..90 without) every step
  double rot_step_deg = 30.0;  ///< candidate rotary angles: a full turn (or its limits) every step
  double noise_um = 0.5;       ///< 1 sigma per latched coordinate (white)
  double reference_radius_mm = 100.0;  ///< an orientation error in rad counts as this lever arm
  ProbeProgramOptions program;  ///< approach, overtravel, clearance: what makes a pose plannable
  /// Each touch its own direction (`rotacal design probe` and rotacal.design.design_probe set it);
  /// false: every visit of a pose along `directions`.
  bool touch_directions = false;
  double max_contact_angle_deg =
      80.0;                        ///< candidate contact points within this of the stylus axis, deg
  double contact_step_deg = 30.0;  ///< their polar angle every this, deg (azimuth every 45)
  std::vector<Eigen::Vector3d>
      sphere_candidates;      ///< other places of the sphere to try, table frame, mm
  double sphere_gain = 0.05;  ///< move the sphere when that lowers the largest U by this fraction
};

/// One place of the sphere the design tried.
struct ProbeSphereTrial {
  Eigen::Vector3d sphere = Eigen::Vector3d::Zero();  ///< table frame, mm
  bool plannable = false;
  double worst_expanded_um = 0.0;  ///< the design there (when plannable)
  std::string why_not;
};

struct ProbeDesignCandidate {
  ProbePattern pattern;  ///< poses (visits, in program order) and directions
  bool feasible = false;
  std::string why_not;             ///< when not feasible
  int touches = 0;                 ///< the pattern's touches (its information scaled to them)
  std::vector<std::string> names;  ///< the fit's parameters
  Eigen::VectorXd sigma;           ///< predicted 1 sigma at the touches, fit units; infinite: held
  double worst_expanded_um = 0.0;  ///< max over the determined location errors of 2 sigma, um
  std::string worst_error;
  /// Location errors no probe pose of the candidates determines (e.g. E_Z0B on a head with the
  /// tool length and the sphere's z): reported, left out of the largest expanded uncertainty. A
  /// design with any is not complete (the JSON's "feasible" is false and says why).
  std::vector<std::string> undetermined;
};

struct ProbeDesign {
  ProbeDesignCandidate best;
  ProbeDesignCandidate baseline;  ///< default_probe_pattern at the same number of touches
  int touches = 0;
  double ratio = 0.0;                ///< best / baseline largest expanded uncertainty
  int poses_tried = 0;               ///< candidate poses that are plannable (at the chosen sphere)
  int touches_tried = 0;             ///< candidate touches (touch by touch; else poses_tried)
  std::vector<std::string> refused;  ///< candidate poses that are not, with the reason (first few)
  Eigen::Vector3d sphere =
      Eigen::Vector3d::Zero();            ///< where the designed test puts the sphere, table frame
  std::vector<ProbeSphereTrial> spheres;  ///< `sphere` then each of sphere_candidates
};

/// Choose the poses and touches. Throws InvalidArgument naming the option for touches < 3,
/// above 100000, not a multiple of the directions or too few to determine the location errors,
/// non-positive steps, noise, diameters or reference radius, a contact angle outside (0, 90] deg,
/// a negative sphere_gain, or no plannable pose at `sphere`.
ProbeDesign design_probe_test(const ProbeDesignOptions& options);

/// The predicted uncertainty of `pattern` at `touches` touches (0: its own). Never throws for
/// a pattern that breaks a limit or leaves a location error undetermined that the design's
/// candidates determine: the candidate says why it is not feasible.
ProbeDesignCandidate evaluate_probe_pattern(const ProbePattern& pattern,
                                            const ProbeDesignOptions& options, int touches);

// ------------------------------------------------------------------ separating two effects

struct ProbeSeparationOptions {
  double tilt_step_deg = 15.0;  ///< grid of the added poses (within the axis limits)
  double rot_step_deg = 30.0;
  double pose_time_s = 0.0;  ///< per pose; 0: the session's (median time between poses)
  double max_added_time_s = 600.0;
  double max_correlation = 0.5;
  double noise_um = 0.0;  ///< 0: the session's residual noise (the probe fit's noise model)
  double reference_radius_mm = 100.0;
  ProbeProgramOptions program;
};

struct ProbeSeparatingCandidate {
  ProbePattern added;  ///< the added poses, the session's sphere and first pose's directions
  std::string description;
  double duration_s = 0.0;  ///< poses x pose time
  double repeats = 1.0;     ///< run this many times
  double correlation = 1.0;
  bool determined = false;
};

/// The engine's result with the probe's chosen poses. Parameters (names): the probe problem's
/// (8 location errors, tool_offset_Z on a head, sphere, the pair); the sphere stays on the table.
struct ProbeSeparationDesign : SeparationResult {
  ProbeSeparatingCandidate chosen;
};

/// The smallest added set of poses (a C sweep at one tilt, a tilt sweep at one C, or one
/// pose, repeated) whose touches, fitted jointly with `session`, bring the largest canonical
/// correlation of the pair below options.max_correlation; or why no test can (the pair moves
/// the table alike: table_motion_overlap). Throws InvalidArgument naming the option for a pair
/// that is not two different effects of the machine, an effect that depends on the motion (the
/// probe reads at rest), a session without touches, or non-positive limits.
ProbeSeparationDesign design_probe_separation(const ProbeSession& session,
                                              const std::vector<Effect>& pair,
                                              const ProbeSeparationOptions& options = {});

}  // namespace rotacal
