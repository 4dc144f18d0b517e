// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Identification of the eight location errors from a single set-up ballbar session:
/// `identify_joint` fits the exact model (model.hpp) to every sample at once through the
/// joint-fit driver (core/joint_fit.hpp); `identify_paper` (identify_paper.hpp) is Flynn et
/// al.'s geometric chain.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/ballbar/model.hpp"
#include "rotacal/core/estimate.hpp"  // ParameterEstimate (kept reachable from this header)
#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/identification.hpp"
#include "rotacal/core/noise_handling.hpp"
#include "rotacal/core/whitener.hpp"

namespace rotacal {

/// A ballbar identification (core/identification.hpp): `parameters` are the 8 location errors,
/// the block "pivot" (x y z), then the extras (dL, effects); `residuals` one per sample of the
/// session (0 for samples not fitted); the Jacobian one row per fitted sample, in session
/// order. Method "joint" or "paper" (identify_paper.hpp).
struct BallbarIdentification : Identification {
  BallbarMachineModel model;  ///< identified machine (unobservable parts left nominal)
};

struct JointFitOptions {
  bool fit_length_offset = false;  ///< add ballbar_length_offset dL to the unknowns
  EffectModel effects;             ///< extra effects to fit along (diagnosis); starts at 0
  std::vector<std::string> tests;  ///< fit only these test labels (empty: all)
  int max_iterations = 100;
  /// A direction in parameter space is unobservable when moving along it by plausible
  /// magnitudes (1 mm, 1 mrad) changes chi-square by less than this.
  double observability_min_chi2 = 1.0;
  /// Optional noise model (GLS): maps the residuals in mm of the fitted samples (session
  /// order) to independent unit-variance ones. The covariance is then (Jw^T Jw)^-1 with no
  /// rescaling, and summary.chi2_per_dof is the whitened one.
  std::shared_ptr<const ResidualWhitener> whitener;
  /// Without a whitener: noise.noise `automatic` estimates the noise model of the first (white)
  /// fit's residuals (one AR stream per test) and, when some stream is correlated, refits with
  /// its ArWhitener so that the covariance holds on correlated data (core/fit_with_noise.hpp);
  /// white data are fitted once, as before. C++ default `white` because the diagnosis refits
  /// through identify_joint with its own whitener decisions; the Python API and the CLI
  /// default to `auto`.
  NoiseFitOptions noise;
};

/// The samples a fit uses as contiguous arrays (structure of arrays): built once per session
/// and reused by every refit (diagnosis candidates, Monte Carlo draws); the test labels are only
/// read by the noise model.
struct BallbarArrays {
  MachineType machine = MachineType::AC_trt;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();  ///< nominal pivot, table frame, mm
  std::optional<double> noise_um;                   ///< declared noise of one reading
  std::size_t session_size = 0;                     ///< samples in the whole session
  std::vector<std::size_t> index;                   ///< session index of each row
  Eigen::Matrix3Xd xyz;                             ///< commanded tool-side ball, mm
  std::vector<RotaryAngles<double>> angles;         ///< rad
  std::vector<RotaryMotion> motion;  ///< rotary_motion of the whole session (empty: not built)
  Eigen::VectorXd time;              ///< s
  Eigen::VectorXd length;            ///< measured length, mm
  std::vector<std::string> test;     ///< test label of each row (noise streams)

  Eigen::Index size() const { return time.size(); }
};

/// The rows of `session` whose test is in `tests` (all if empty), as arrays. `with_motion`
/// false leaves `motion` empty, for a fit none of whose effects depends on the motion.
BallbarArrays ballbar_arrays(const BallbarSession& session,
                             const std::vector<std::string>& tests = {}, bool with_motion = true);

/// Joint least-squares fit of location errors + actual pivot (+ dL, + effects) to every
/// sample: residual_i = (L_model,i - L_i) / sigma, Jacobians by Jets of the one model
/// (model.hpp) over the whole batch. Starts from zero errors and the nominal pivot. The 1-sigma
/// covariance is (J^T J)^-1 s^2 with s^2 the residual variance (GLS with options.whitener);
/// parameters the tests cannot see are held at zero and reported as unobservable.
/// Throws InvalidArgument for a session with fewer samples than unknowns.
BallbarIdentification identify_joint(const BallbarSession& session,
                                     const JointFitOptions& options = {});

/// The same fit on prepared arrays (options.tests was applied when they were built and is
/// ignored here).
BallbarIdentification identify_joint(const BallbarArrays& data,
                                     const JointFitOptions& options = {});

}  // namespace rotacal
