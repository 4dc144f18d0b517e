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
#include <vector>

#include "rotacal/core/machine_model.hpp"
#include "rotacal/io/session.hpp"
#include "rotacal/rtest/model.hpp"

namespace rotacal {

/// Measurement pattern. Defaults: the paper's B = -90..90 every 30 deg, C = 0..330 every 30 deg
/// (84 poses per nest), and the two nests of rtest_bc_oyama.csv. Poses run B outer, C inner.
struct RtestPattern {
  std::vector<double> b_deg = {-90, -60, -30, 0, 30, 60, 90};                      ///< deg
  std::vector<double> c_deg = {0, 30, 60, 90, 120, 150, 180, 210, 240, 270, 300, 330};  ///< deg
  std::vector<Eigen::Vector3d> nests = {Eigen::Vector3d(100, 0, 60),
                                        Eigen::Vector3d(0, -120, 140)};  ///< table frame, mm
  double dwell_s = 6.0;  ///< time between poses, s; the program holds each pose at rest for the middle 80 % (hw/pose_window.hpp)
};

struct RtestSimOptions {
  RtestPattern pattern;
  double noise_um = 0.3;        ///< 1 sigma per probe reading (or per d component), um
  double probe_zero_um = 20.0;  ///< 1 sigma of each component of the random per-set-up zero, um
  /// If set: rows are probe directions; raw d1,d2,d3 = Dirs (d + zero) + noise are written with
  /// probe.N.dir metadata, and d = Dirs^-1 raw. Otherwise the noise is added to d directly.
  std::optional<Eigen::Matrix3d> probe_dirs;
  bool write_d = true;  ///< with probe_dirs: also fill dx,dy,dz (false: raw only)
  unsigned seed = 1;
};

struct RtestSimulation {
  RtestSession session;
  std::vector<Eigen::Vector3d> probe_zeros;  ///< per set-up (nest order), table frame, mm
};

/// Simulate a whole session; each reading is rtest_reading (model.hpp). Throws
/// InvalidArgument for an empty pattern, negative noise or effect parameters that do not
/// match the effect model.
RtestSimulation simulate_rtest(const MachineModel& truth, const RtestSimOptions& options = {});

}  // namespace rotacal
