#pragma once
/// \file
/// Joint identification of an R-test session: one least-squares problem (core/joint_fit.hpp)
/// for the 8 location errors, the position-dependent errors of both axes in a smooth basis,
/// and an unknown probe zero per set-up, with Jacobians by Jets of the one reading
/// (rtest/model.hpp). The model (error_model.hpp, rtest_table_pose):
///   T(B, C) = E(w_BY(B)) Rot(B line, B) E(w_CB(B, C)) Rot(C line, C)
///   d       = T^-1 xyz - q_nest + zero_setup
/// w_BY, w_CB are the deviations beyond the rigid axis lines (Oyama's errors with the location
/// errors taken out). Basis, with b = B / 90 deg:
///   w_BY translations (dx, dy, dz): even powers b^2, b^4, ... <= b_degree
///   w_BY rotations (alpha, beta, gamma): odd powers b, b^3, ... <= b_degree
///   w_CB component k: sum_{n=1..K} sum_{m=0..M} b^m (a cos nC + s sin nC)
/// Why the parities: a location error of the B axis moves (dx, dz) and (alpha, gamma) in pairs
/// with the signature (1 - cos B, sin B), one even and one odd function; a map with only one
/// parity per pair cannot imitate it, so location errors and map stay separable. Gravity sag
/// (even in B) and coning (odd, Oyama Sec. 5.3) are inside the basis; odd translations and even
/// rotations of the B axis beyond its location errors are outside it (a stated limit). The C map
/// has no constant term (that is the B map's and the location errors' job), and its first
/// harmonic of (dx, dy) and of (alpha, beta) at b^0 turns backwards only: a translation or tilt
/// that turns forwards with C is constant in the table frame, which the probe zeros absorb.

#include <map>
#include <string>
#include <vector>

#include <memory>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/noise_handling.hpp"
#include "rotacal/core/whitener.hpp"
#include "rotacal/io/session.hpp"
#include "rotacal/rtest/error_model.hpp"
#include "rotacal/rtest/model.hpp"

namespace rotacal {

/// Shape of the smooth basis of the position-dependent errors.
struct RtestBasis {
  int b_degree = 6;     ///< highest power of b = B/90deg in the B map (0: no B map)
  int c_harmonics = 2;  ///< harmonics 1..K of C in the C map (0: no C map)
  int c_b_degree = 1;   ///< C-map coefficients are polynomials of degree 0..M in b
  /// Include gamma_CB (angular positioning of C) in the C map. Off by default, as Oyama Sec. 4.2
  /// assumes: two nests see 5 of the table's 6 degrees of freedom per pose, and gamma_CB's first
  /// harmonic is then confounded with the C axis' orientation (needs 3 nests).
  bool gamma_cb = false;

  int num_b_coefficients() const;
  int num_c_coefficients() const;
  /// Names "dz_BY.b2", "dx_CB.cos1.b0", ... in coefficient order (B map first).
  std::vector<std::string> coefficient_names() const;
  /// Basis values of w_BY component k (0..5) at B (rad): coefficients of that component.
  std::vector<double> b_terms(int k, double B) const;
  /// Contribution of each C-map coefficient (in order) to w_CB at (B, C) (rad).
  std::vector<AxisErrors<double>> c_terms(double B, double C) const;
};

/// Everything needed to predict: location errors, map coefficients and their covariance.
struct RtestJointModel {
  MachineType machine = MachineType::BC_trt;
  RtestBasis basis;
  /// Parameters in order [8 location errors, B-map coefficients, C-map coefficients].
  Eigen::VectorXd params;
  /// 1-sigma^2 covariance of params (zero rows/cols for parameters held fixed).
  Eigen::MatrixXd covariance;
  std::vector<bool> observable;  ///< per param

  LocationErrors<double> errors() const;
  /// w_BY(B) and w_CB(B, C) (mm, rad) with 1-sigma (NaN where an unobservable parameter enters).
  AxisErrors<double> w_BY(double B, AxisErrors<double>* std = nullptr) const;
  AxisErrors<double> w_CB(double B, double C, AxisErrors<double>* std = nullptr) const;
  Pose<double> table_pose(double B, double C) const;
  /// R-test reading of the nest at q (table frame) at (B, C), without probe zero, with 1 sigma.
  Eigen::Vector3d reading(const Eigen::Vector3d& q, double B, double C,
                          Eigen::Vector3d* std = nullptr) const;
  /// Error of the table point q at (B, C): T q - T_nominal q, machine frame (mm), with 1 sigma.
  Eigen::Vector3d table_error(const Eigen::Vector3d& q, double B, double C,
                              Eigen::Vector3d* std = nullptr) const;
};

/// Templated evaluation of the joint model's table pose (any Scalar): e -> 8 location errors,
/// cb -> B-map coefficients, cc -> C-map coefficients.
template <typename Scalar>
Pose<Scalar> rtest_joint_table_pose(const RtestBasis& basis, const Scalar* e, const Scalar* cb,
                                    const Scalar* cc, double B, double C) {
  AxisErrors<Scalar> wb = AxisErrors<Scalar>::Zero(), wc = AxisErrors<Scalar>::Zero();
  int o = 0;
  for (int k = 0; k < 6; ++k)
    for (double phi : basis.b_terms(k, B)) wb[k] += cb[o++] * Scalar(phi);
  o = 0;
  for (const AxisErrors<double>& t : basis.c_terms(B, C)) {
    for (int k = 0; k < 6; ++k)
      if (t[k] != 0.0) wc[k] += cc[o] * Scalar(t[k]);
    ++o;
  }
  return rtest_table_pose<Scalar>(LocationErrors<Scalar>::from_ptr(e), wb, wc, Scalar(B), Scalar(C));
}

/// The joint model's R-test reading (rtest/model.hpp) for the sphere commanded to xyz (mm)
/// over the nest at q_nest, at B, C (rad): location errors e and the maps' values w_BY, w_CB
/// at this pose. The joint fit takes Jets of it with respect to (e, w_BY, w_CB); the map
/// coefficients enter through the (linear) basis.
template <typename Scalar>
Vec3<Scalar> rtest_joint_reading(const LocationErrors<Scalar>& e, const AxisErrors<Scalar>& w_BY,
                                 const AxisErrors<Scalar>& w_CB, double B, double C,
                                 const Eigen::Vector3d& xyz, const Eigen::Vector3d& q_nest) {
  return rtest_displacement<Scalar>(rtest_table_pose<Scalar>(e, w_BY, w_CB, Scalar(B), Scalar(C)),
                                    xyz.cast<Scalar>(), q_nest);
}

struct RtestJointOptions {
  RtestBasis basis;
  int max_iterations = 50;
  /// A direction is unobservable when moving along it by plausible magnitudes (1 mm, 1 mrad)
  /// changes chi-square by less than this (core/least_squares.hpp).
  double observability_min_chi2 = 1.0;
  /// Optional noise model (GLS): maps the residuals in mm (3 per sample, dx dy dz, session
  /// order) to independent unit-variance ones; the covariance is then (Jw^T Jw)^-1 and
  /// summary.chi2_per_dof the whitened one.
  std::shared_ptr<const ResidualWhitener> whitener;
  /// Without a whitener: `automatic` estimates the noise model of the first fit's residuals
  /// (one AR stream per nest and channel dx, dy, dz, in time order; probe zeros that wander
  /// between poses show as correlation) and refits by GLS when it is not white.
  /// C++ default `white` (as before) because the diagnosis refits through identify_joint
  /// with its own whitener decisions; the Python API and the CLI default to `auto`.
  NoiseHandling noise = NoiseHandling::white;
  NoiseModelOptions noise_options;
  /// The GLS refit is done only when some stream's integrated correlation time reaches this
  /// (samples): below it the white covariance is within ~10 % and BIC's rare spurious AR(1) of
  /// white noise (|phi| ~ 0.05) must not change the answer.
  double min_correlation_samples = 1.2;
  /// Scale the GLS covariance by the bootstrap bias factor (core/noise_handling.hpp).
  bool noise_bias_correction = true;
};

struct RtestJointIdentification {
  std::string method = "joint";
  RtestJointModel model;
  std::vector<ParameterEstimate> parameters;  ///< location errors, map coefficients, zeros
  Eigen::MatrixXd covariance;                 ///< in `parameters` order
  std::map<std::string, Eigen::Vector3d> probe_zeros;  ///< per set-up, mm
  std::vector<Eigen::Vector3d> residuals;     ///< measured - model per sample, mm
  double residual_rms_um = 0.0;               ///< over all components
  double sigma_um = 0.0;                      ///< dof-corrected residual sigma used for covariance
  std::size_t n_samples = 0;
  bool converged = false;
  int iterations = 0;
  std::vector<std::string> unobservable;  ///< combinations the nests cannot see, in words
  std::vector<std::string> notes;
  FitSummary summary;  ///< solver figures; whitened chi2/dof with a whitener
  NoiseModel noise;          ///< noise model of the residuals (streams: nest x channel)
  /// Factor applied to the GLS covariance for the noise model's bias (estimated from
  /// residuals that the fit has already taken the slow noise from): core/noise_handling.hpp.
  double noise_correction = 1.0;
  bool noise_refit = false;  ///< the fit was redone by GLS under `noise`

  const ParameterEstimate& parameter(const std::string& name) const;
};

/// Fit the joint model to every sample. Throws InvalidArgument for a non-BC-trt session,
/// samples without d (convert raw readings first: device.hpp), unknown nests, or fewer
/// readings than unknowns.
RtestJointIdentification identify_joint(const RtestSession& session,
                                        const RtestJointOptions& options = {});

}  // namespace rotacal
