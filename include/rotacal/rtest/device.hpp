// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The R-test device (Oyama & Ibaraki, Sec. 3.1-3.2): a precision sphere in the spindle and three
/// displacement probes fixed on the table (one "nest"), and its calibration.
///
/// Reading model (flat-ended probes on a sphere). Probe i has a flat measuring face whose normal
/// is the unit vector `dir_i` (table frame, the direction in which a positive displacement of the
/// sphere gives a positive reading). The face stays tangent to the sphere, and a sphere's support
/// function is linear in its translation, so for a sphere-centre displacement d (table frame)
///     reading_i = dir_i . d + zero_i                         (exact)
/// i.e. readings = Dirs d + zero with Dirs = [dir_1; dir_2; dir_3] (rows), and d = Dirs^-1
/// (readings - zero). Limits: exact only while the contact point stays on the flat face (lateral
/// displacement |d - (dir.d) dir| below the face radius minus nothing else) and for a perfect
/// sphere; a ball-ended probe adds a second-order cosine error ~|d_perp|^2 / (2 (R + r)); probe
/// gain errors appear as a non-unit |dir| (calibrate_probe_directions reports them); the
/// directions must be linearly independent (cond(Dirs) is checked).
///
/// Calibration (Sec. 3.2): (1) probe directions from known linear moves of the sphere with the
/// rotary axes at 0 (table frame = machine frame, linear-axis errors neglected), linear least
/// squares per probe for gain*dir and the probe zero; (2) the sphere's offset from the spindle
/// axis from readings at a set of spindle indexing angles: the centre runs on a circle about the
/// spindle axis, c + Rz(theta) o, fitted linearly.

#include <Eigen/Core>
#include <vector>

#include "rotacal/kinematics/rotation.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// Probe readings (mm) of a sphere-centre displacement d (table frame, mm): Dirs * d.
/// `dirs` rows are the probe directions.
template <typename Scalar>
Vec3<Scalar> probe_readings(const Mat3<Scalar>& dirs, const Vec3<Scalar>& d) {
  return dirs * d;
}

/// Sphere-centre displacement (table frame, mm) from three probe readings (mm): Dirs^-1 * r.
/// Throws DegenerateGeometry if the directions are (nearly) linearly dependent (cond > 1e6).
Eigen::Vector3d sphere_displacement(const Eigen::Matrix3d& dirs, const Eigen::Vector3d& readings);

/// One commanded linear move for the direction calibration and the readings it gave.
struct ProbeCalibrationSample {
  Eigen::Vector3d move = Eigen::Vector3d::Zero();      ///< commanded sphere displacement, mm
  Eigen::Vector3d readings = Eigen::Vector3d::Zero();  ///< d1, d2, d3, mm
};

/// Result of calibrate_probe_directions.
struct ProbeCalibration {
  Eigen::Matrix3d dirs = Eigen::Matrix3d::Identity();  ///< unit directions (rows)
  Eigen::Vector3d gains = Eigen::Vector3d::Ones();     ///< |gain * dir| per probe (1 = ideal)
  Eigen::Vector3d zeros = Eigen::Vector3d::Zero();     ///< probe zero offsets, mm
  Eigen::Vector3d direction_std_rad = Eigen::Vector3d::Zero();  ///< 1-sigma angular uncertainty
  Eigen::Vector3d gain_std = Eigen::Vector3d::Zero();           ///< 1-sigma of the gains
  std::vector<Eigen::Vector3d> residuals;  ///< measured - model reading per sample, mm
  double residual_rms_um = 0.0;
  double sigma_um = 0.0;  ///< residual standard deviation (dof-corrected), um
};

/// Identify the probe directions (and gains, zeros) from known linear moves (Sec. 3.2).
/// Per probe i: reading_ik = g_i . move_k + zero_i, linear least squares in (g_i, zero_i);
/// dir_i = g_i / |g_i|. Needs >= 5 moves spanning 3-D: throws InvalidArgument (too few samples)
/// or DegenerateGeometry (moves do not span 3-D).
ProbeCalibration calibrate_probe_directions(const std::vector<ProbeCalibrationSample>& samples);

/// Simulated direction-calibration readings: readings = gains_i dir_i . move + zero_i + noise.
std::vector<ProbeCalibrationSample> simulate_probe_calibration(
    const Eigen::Matrix3d& dirs, const Eigen::Vector3d& zeros,
    const std::vector<Eigen::Vector3d>& moves, double noise_um, unsigned seed);

/// Default moves: +-step along X, Y, Z and the 4 body diagonals (14 moves), mm.
std::vector<Eigen::Vector3d> default_calibration_moves(double step_mm = 0.5);

/// Spindle indexing sample: spindle angle (rad) and the three readings (mm).
struct SpindleIndexSample {
  double angle = 0.0;
  Eigen::Vector3d readings = Eigen::Vector3d::Zero();
};

/// Result of calibrate_sphere_offset.
struct SphereOffsetCalibration {
  Eigen::Vector2d offset =
      Eigen::Vector2d::Zero();  ///< sphere centre - spindle axis at angle 0 (x, y), mm
  Eigen::Vector2d offset_std = Eigen::Vector2d::Zero();  ///< 1 sigma, mm
  Eigen::Vector3d centre =
      Eigen::Vector3d::Zero();  ///< spindle-axis point in probe coordinates (incl. zeros), mm
  double residual_rms_um = 0.0;
};

/// Sphere offset from the spindle axis from spindle indexing (Sec. 3.2): the displacement
/// d_k = Dirs^-1 r_k = c + Rz(theta_k) o, linear least squares in (c, o). Needs >= 3 distinct
/// angles (throws InvalidArgument / DegenerateGeometry).
SphereOffsetCalibration calibrate_sphere_offset(const Eigen::Matrix3d& dirs,
                                                const std::vector<SpindleIndexSample>& samples);

/// Simulated spindle indexing: centre = c + Rz(angle) [offset, 0], readings = Dirs centre +
/// zero + noise.
std::vector<SpindleIndexSample> simulate_spindle_indexing(const Eigen::Matrix3d& dirs,
                                                          const Eigen::Vector3d& zeros,
                                                          const Eigen::Vector2d& offset,
                                                          const Eigen::Vector3d& centre,
                                                          const std::vector<double>& angles,
                                                          double noise_um, unsigned seed);

/// The sphere offset o (x, y, at the spindle orientation used during the R-test) displaces the
/// actual sphere by H (o, 0) in the machine frame (H the head's nominal rotation at the pose,
/// identity without head axes), which the table frame sees as R^T H (o, 0) (R the table's
/// nominal rotation, Ry(B) Rz(C) on BC-trt): returns the session with that subtracted from
/// every d. Any machine.
RtestSession compensate_sphere_offset(const RtestSession& session, const Eigen::Vector2d& offset);

/// Fill dx,dy,dz from raw d1,d2,d3 with the session's probe.N.dir (N = 1..3), d = Dirs^-1 raw.
/// Rows that already have d keep it. Throws InvalidArgument if a row has neither, or raw rows
/// exist and probe.1..3.dir are missing.
RtestSession displacements_from_raw(const RtestSession& session);

/// The same with explicitly calibrated directions (overrides the session's probe.N.dir).
RtestSession displacements_from_raw(const RtestSession& session, const Eigen::Matrix3d& dirs);

}  // namespace rotacal
