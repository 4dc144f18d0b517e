// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// R-test simulator (Oyama & Ibaraki, Sec. 3.3): the sphere follows each sensor nest while the
/// table visits a grid of (B, C); the readings come from the exact model of kinematics/effects.hpp
/// (location errors + catalogue effects), a per-set-up probe zero and Gaussian noise.
///
/// One reading, table frame (the convention checked on ../shared/data/rtest_bc_oyama.csv):
///   xyz = forward(nominal, B, C, q_nest)                 commanded sphere centre
///   d   = T(B, C, t)^-1 * tool_position(xyz, t) - q_nest + zero_setup + noise

#include <optional>
#include <string>
#include <vector>

#include "rotacal/kinematics/machine_model.hpp"
#include "rotacal/rtest/model.hpp"
#include "rotacal/session/session.hpp"
#include "rotacal/session/thermal_test.hpp"

namespace rotacal {

/// Measurement pattern. Defaults: the paper's B = -90..90 every 30 deg, C = 0..330 every 30 deg
/// (84 poses per nest), and the two nests of rtest_bc_oyama.csv. Poses run B outer, C inner.
/// On any machine b_deg are the tilt axis' angles and c_deg the rotary axis' (RotaryAngles);
/// default_rtest_pattern fits them and the nests to a machine's limits.
struct RtestPattern {
  std::vector<double> b_deg = {-90, -60, -30, 0, 30, 60, 90};  ///< tilt, deg
  std::vector<double> c_deg = {0,   30,  60,  90,  120, 150,
                               180, 210, 240, 270, 300, 330};  ///< rotary, deg
  std::vector<Eigen::Vector3d> nests = {Eigen::Vector3d(100, 0, 60),
                                        Eigen::Vector3d(0, -120, 140)};  ///< table frame, mm
  double dwell_s = 6.0;  ///< time between poses, s; the program holds each pose at rest for the
                         ///< middle 80 % (hw/pose_window.hpp)
  /// Poses (tilt, rot, deg) in visiting order; non-empty: they replace the b_deg x c_deg grid
  /// in simulate_rtest and check_rtest_pattern (a thermal epoch's few poses; design_rtest
  /// chooses grids only).
  std::vector<RotaryAngles<double>> poses_deg;
  /// The poses visited, deg: poses_deg, or the grid with B outer and C inner.
  std::vector<RotaryAngles<double>> poses() const;
};

/// The paper's pattern fitted to machine m: seven tilt angles over the widest span of at most
/// 180 deg inside the tilt axis' limits, centred on 0 where the limits allow (-90..90 every 30
/// deg when they do; 0..180 on a nutating table whose B turns 0..180); twelve rotary angles
/// every 30 deg (spread over the limits of a rotary axis that turns less than a full turn);
/// the two nests of rtest_bc_oyama.csv, each halved (up to four times) until every commanded
/// X, Y, Z lies inside the machine's travel. Throws InvalidArgument naming the nest when no
/// halving fits.
RtestPattern default_rtest_pattern(MachineType m);

/// Throws InvalidArgument, naming `context`, the axis and its limits (or the travel), when a
/// pattern angle lies outside the machine's rotary limits or a commanded X, Y, Z outside its
/// travel.
void check_rtest_pattern(MachineType m, const RtestPattern& pattern, const std::string& context);

struct RtestSimOptions {
  RtestPattern pattern;
  double noise_um = 0.3;        ///< 1 sigma per probe reading (or per d component), um
  double probe_zero_um = 20.0;  ///< 1 sigma of each component of the random per-set-up zero, um
  /// If set: rows are probe directions; raw d1,d2,d3 = Dirs (d + zero) + noise are written with
  /// probe.N.dir metadata, and d = Dirs^-1 raw. Otherwise the noise is added to d directly.
  std::optional<Eigen::Matrix3d> probe_dirs;
  bool write_d = true;  ///< with probe_dirs: also fill dx,dy,dz (false: raw only)
  unsigned seed = 1;
  /// Correlation of each reading's noise from one pose to the next within a set-up (AR(1),
  /// core/noise_model.hpp noise_gen::ar1); 0: independent draws.
  double ar1_rho = 0.0;
  /// A thermal test (formats.md): the pattern once per epoch for each nest, the location errors
  /// and every nest drifting as thermal_location_R. None: one pass from 0 s.
  std::optional<ThermalSimSpec> thermal;
};

struct RtestSimulation {
  RtestSession session;
  std::vector<Eigen::Vector3d> probe_zeros;  ///< per set-up (nest order), table frame, mm
  ThermalTest thermal;  ///< with options.thermal: the duty, each row's epoch and time
};

/// Simulate a whole session on any machine; each reading is rtest_reading (model.hpp), with the
/// tool-length error of a head machine taken from tool_offset_Z among the effects. Throws
/// InvalidArgument for an empty pattern, a pattern outside the machine's limits
/// (check_rtest_pattern), negative noise, |ar1_rho| >= 1, effect parameters that do not match
/// the effect model, or a thermal spec ThermalSimSpec::validate refuses. A thermal test keeps
/// each nest mounted over the whole session (one set-up, one probe zero): each epoch visits
/// every nest in turn.
RtestSimulation simulate_rtest(const MachineModel& truth, const RtestSimOptions& options = {});

}  // namespace rotacal
